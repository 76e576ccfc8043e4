#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "pspslam/camera/pinhole_camera.h"
#include "pspslam/core/types.h"
#include "pspslam/occupancy/occupancy_options.h"

namespace pspslam {

// What one keyframe adds to the occupancy map: its depth readings as points in its camera frame
// (the dynamic pixels of its mask left out), kept so that the map can be rebuilt when the
// keyframe moves.
struct KeyframeScan {
  std::uint64_t keyframe_id = 0;
  std::vector<Eigen::Vector3f> points;  // camera frame, metres
};

// `depth`: CV_32F metres (0 = no reading); `dynamic_mask`: CV_8U, non-zero = dynamic (may be
// empty). Every options.pixel_stride-th pixel, undistorted through `camera`.
KeyframeScan make_keyframe_scan(std::uint64_t keyframe_id, const PinholeCamera& camera,
                                const cv::Mat& depth, const cv::Mat& dynamic_mask,
                                const OccupancyOptions& options);

// The occupancy map of the static scene: an OctoMap (probabilistic octree, log-odds per voxel)
// in the SLAM world frame. Each scan casts a ray from the camera to each point: the end voxel is
// evidence of occupancy, the voxels before it (with clearing) of free space, so a person who
// stood still and then left is cleared by the rays that later pass where they stood. Not
// thread-safe: the OccupancyMapper guards it.
class OccupancyMap {
 public:
  explicit OccupancyMap(const OccupancyOptions& options);
  ~OccupancyMap();
  OccupancyMap(OccupancyMap&&) noexcept;
  OccupancyMap& operator=(OccupancyMap&&) noexcept;

  void insert(const KeyframeScan& scan, const Pose& T_world_camera);
  void clear();

  double resolution() const;
  size_t memory_bytes() const;
  size_t inserted_scans() const;
  // Every known voxel at the map's resolution (large uniform nodes expanded), world frame.
  void for_each_voxel(
      const std::function<void(const Eigen::Vector3d& centre, bool occupied)>& visit) const;
  std::optional<bool> occupied_at(const Eigen::Vector3d& point) const;  // none: unknown
  // Whether a voxel within one voxel (26-neighbourhood) of `point` is occupied.
  bool occupied_near(const Eigen::Vector3d& point) const;

  // Occupied voxels (centres) that a ray of a scan inserted after the voxel's first hit passes
  // through, ending at least three voxels behind it: what later views saw through. `scans` in
  // insertion order, with their poses.
  std::vector<Eigen::Vector3d> seen_through(
      const std::vector<std::pair<const KeyframeScan*, Pose>>& scans) const;

  // OctoMap's binary format (.bt, maximum-likelihood occupancy; octovis reads it). Throws
  // pspslam::Error naming the file.
  void write_binary(const std::filesystem::path& file) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pspslam
