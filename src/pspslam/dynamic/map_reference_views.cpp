#include "pspslam/dynamic/map_reference_views.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <opencv2/calib3d.hpp>
#include <utility>

#include "pspslam/map/keyframe.h"
#include "pspslam/map/map.h"

namespace pspslam {

cv::Mat rebuild_reference_depth(const KeyFrame& keyframe, const PinholeCamera& camera,
                                int splat_radius_px) {
  cv::Mat depth = cv::Mat::zeros(camera.height, camera.width, CV_32FC1);
  std::vector<cv::Point3f> rays;
  std::vector<float> depths;
  for (int i = 0; i < keyframe.size(); ++i) {
    if (!keyframe.has_depth(i)) continue;
    const cv::Point2f& pixel = keyframe.keypoints()[i].pt;
    rays.emplace_back(static_cast<float>((pixel.x - camera.cx) / camera.fx),
                      static_cast<float>((pixel.y - camera.cy) / camera.fy), 1.0f);
    depths.push_back(keyframe.depth(i));
  }
  if (rays.empty()) return depth;
  // Back to distorted pixels: the live depth images the test also reads are registered to the
  // raw (distorted) colour image.
  std::vector<cv::Point2f> pixels;
  cv::projectPoints(rays, cv::Vec3d::zeros(), cv::Vec3d::zeros(), camera.K(),
                    camera.distortion_coeffs(), pixels);
  for (size_t i = 0; i < pixels.size(); ++i) {
    const int u = static_cast<int>(std::lround(pixels[i].x));
    const int v = static_cast<int>(std::lround(pixels[i].y));
    for (int y = std::max(0, v - splat_radius_px);
         y <= std::min(camera.height - 1, v + splat_radius_px); ++y) {
      float* row = depth.ptr<float>(y);
      for (int x = std::max(0, u - splat_radius_px);
           x <= std::min(camera.width - 1, u + splat_radius_px); ++x) {
        if (row[x] == 0.0f || depths[i] < row[x]) row[x] = depths[i];
      }
    }
  }
  return depth;
}

MapReferenceViews::MapReferenceViews(const Map& map, const PinholeCamera& camera,
                                     MapReferenceParams params)
    : params_(params) {
  for (const auto& keyframe : map.keyframes()) {
    if (keyframe->is_bad()) continue;
    views_.push_back(
        {keyframe, rebuild_reference_depth(*keyframe, camera, params.splat_radius_px)});
  }
}

void MapReferenceViews::pool(const Pose& T_world_camera, size_t pool_size,
                             std::vector<DepthView>& out) const {
  out.clear();
  const double min_axis_cos = std::cos(params_.max_axis_angle_deg * std::numbers::pi / 180.0);
  const Eigen::Vector3d axis = T_world_camera.rotation().col(2);
  std::vector<std::pair<double, DepthView>> candidates;
  for (const View& view : views_) {
    const auto keyframe = view.keyframe.lock();
    if (!keyframe || keyframe->is_bad()) continue;
    const Pose T_world_reference = keyframe->T_world_camera();
    if (T_world_reference.rotation().col(2).dot(axis) < min_axis_cos) continue;
    const double distance = (T_world_reference.translation() - T_world_camera.translation()).norm();
    candidates.push_back({distance, {T_world_reference, view.depth}});
  }
  const size_t keep = std::min(pool_size, candidates.size());
  std::partial_sort(candidates.begin(), candidates.begin() + static_cast<std::ptrdiff_t>(keep),
                    candidates.end(),
                    [](const auto& a, const auto& b) { return a.first < b.first; });
  for (size_t i = 0; i < keep; ++i) out.push_back(std::move(candidates[i].second));
}

}  // namespace pspslam
