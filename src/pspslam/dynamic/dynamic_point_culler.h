#pragma once

#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <span>
#include <unordered_map>
#include <vector>

#include "pspslam/camera/pinhole_camera.h"
#include "pspslam/core/types.h"

namespace pspslam {

class MapPoint;

struct DynamicCullingParams {
  // A map point is culled once it has been seen on dynamic pixels in this many frames.
  int min_dynamic_hits = 3;
  // "Seen on" = projects into the dynamic mask *and* its depth agrees with the measured depth
  // there (abs + relative * depth): a static point merely occluded by a person is not on it.
  double depth_tolerance_abs_m = 0.05;
  double depth_tolerance_relative = 0.03;
};

// Counts, per map point, the frames in which it lay on dynamic pixels and reports the points that
// reached the threshold (points created on a person before she was detected -- e.g. she
// stood still in the first frames -- must leave the map once she is known to be dynamic).
// Not thread-safe: used by the tracking thread only. Buffers are reused.
class DynamicPointCuller {
 public:
  explicit DynamicPointCuller(DynamicCullingParams params = {}) : params_(params) {}

  // `points`: map points to check (e.g. the tracker's local map); `dynamic_mask` CV_8UC1 and
  // `depth` CV_32FC1 metres of the current frame with pose `T_world_camera`. Returns the points
  // that reached the threshold (they are forgotten here; the caller erases them from the Map).
  const std::vector<std::shared_ptr<MapPoint>>& observe(
      std::span<const std::shared_ptr<MapPoint>> points, const Pose& T_world_camera,
      const cv::Mat& dynamic_mask, const cv::Mat& depth, const PinholeCamera& camera);

 private:
  DynamicCullingParams params_;
  std::unordered_map<std::uint64_t, int> hits_;
  std::vector<std::shared_ptr<MapPoint>> to_cull_;
};

}  // namespace pspslam
