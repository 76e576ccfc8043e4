#include "pspslam/dynamic/dynamic_point_culler.h"

#include <cmath>

#include "pspslam/map/map_point.h"

namespace pspslam {

const std::vector<std::shared_ptr<MapPoint>>& DynamicPointCuller::observe(
    std::span<const std::shared_ptr<MapPoint>> points, const Pose& T_world_camera,
    const cv::Mat& dynamic_mask, const cv::Mat& depth, const PinholeCamera& camera) {
  to_cull_.clear();
  if (dynamic_mask.empty() || depth.empty()) return to_cull_;
  const Pose T_camera_world = T_world_camera.inverse();
  for (const auto& point : points) {
    if (!point || point->is_bad()) continue;
    const Eigen::Vector3d p = T_camera_world * point->position();
    if (p.z() <= 0.0) continue;
    const Eigen::Vector2d pixel = camera.project(p);
    const int u = static_cast<int>(std::lround(pixel.x()));
    const int v = static_cast<int>(std::lround(pixel.y()));
    if (u < 0 || v < 0 || u >= dynamic_mask.cols || v >= dynamic_mask.rows) continue;
    if (!dynamic_mask.at<std::uint8_t>(v, u)) continue;
    const float measured = depth.at<float>(v, u);
    if (measured <= 0.0f) continue;
    const double tolerance =
        params_.depth_tolerance_abs_m + params_.depth_tolerance_relative * measured;
    if (std::abs(measured - p.z()) > tolerance) continue;
    int& hits = hits_[point->id()];
    if (++hits >= params_.min_dynamic_hits) {
      to_cull_.push_back(point);
      hits_.erase(point->id());
    }
  }
  return to_cull_;
}

}  // namespace pspslam
