#pragma once

// A synthetic RGB-D world for the mapping tests: static points with a fixed random descriptor
// each, cameras on a path, and keyframes built through the real Frame/KeyFrame constructors as
// tracking would build them (keypoints, depth image, descriptors, pose, map point associations).

#include <map>
#include <memory>
#include <random>
#include <vector>

#include "pspslam/map/camera_model.h"
#include "pspslam/map/keyframe.h"
#include "pspslam/map/map.h"
#include "pspslam/map/map_point.h"
#include "pspslam/map/scale_pyramid.h"

namespace pspslam::testing {

struct WorldPoint {
  Eigen::Vector3d position;
  cv::Mat descriptor;     // 1×32 CV_8U
  bool has_depth = true;  // false: the sensor returns no depth there (needs triangulation)
  std::int64_t only_in_keyframe = -1;  // >= 0: a transient feature seen by that keyframe only
};

class SyntheticWorld {
 public:
  // num_points points in a box 1.5–5 m in front of the start, a fraction without depth.
  SyntheticWorld(int num_points, double no_depth_fraction, uint32_t seed);

  const std::shared_ptr<const CameraModel>& camera() const { return camera_; }
  const std::shared_ptr<const ScalePyramid>& pyramid() const { return pyramid_; }
  const std::vector<WorldPoint>& points() const { return points_; }

  // Adds a point seen only by keyframe `keyframe_id` (a spurious / dynamic feature).
  int add_transient_point(const Eigen::Vector3d& position, std::uint64_t keyframe_id);

  // Builds keyframe `id` seen from T_camera_world_true (1 px pixel noise at level 0, exact depth
  // on the point's pixel), gives it `estimated_T_camera_world`, and associates every keypoint
  // whose world point already has a map point in `map` (as tracking would after matching).
  // A fraction of those associations can be made wrong (another, random map point), as bad
  // matches are.
  std::shared_ptr<KeyFrame> make_keyframe(std::uint64_t id, const Pose& T_camera_world_true,
                                          const Pose& estimated_T_camera_world, const Map& map,
                                          double wrong_association_fraction = 0.0);

  // World point index behind keypoint `index` of keyframe `keyframe_id` (-1: none).
  int world_index(std::uint64_t keyframe_id, int index) const;
  // World point that a map point stands for (via its first live observation), -1 if unknown.
  int world_index(const MapPoint& point) const;

 private:
  std::shared_ptr<const CameraModel> camera_;
  std::shared_ptr<const ScalePyramid> pyramid_;
  std::vector<WorldPoint> points_;
  std::map<std::uint64_t, std::vector<int>> keypoint_world_index_;
  std::mt19937 rng_;
};

// Camera k of a sideways path looking down +z (T_camera_world).
Pose path_pose(int k, double step_metres = 0.12, double yaw_step = 0.03);
Pose perturbed(const Pose& pose, double angle_rad, double translation_m, std::mt19937& rng);
double rotation_error_deg(const Pose& a, const Pose& b);
double center_error(const Pose& T_camera_world_a, const Pose& T_camera_world_b);

}  // namespace pspslam::testing
