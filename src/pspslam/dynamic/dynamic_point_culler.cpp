#include "pspslam/dynamic/dynamic_point_culler.h"

#include <cmath>

#include "pspslam/core/error.h"
#include "pspslam/map/map_point.h"

namespace pspslam {

Eigen::Vector2d project_distorted(const PinholeCamera& camera, const Eigen::Vector3d& point) {
  const double x = point.x() / point.z(), y = point.y() / point.z();
  const auto& [k1, k2, p1, p2, k3] = camera.distortion;
  const double r2 = x * x + y * y;
  const double radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
  const double xd = x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x);
  const double yd = y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y;
  return {camera.fx * xd + camera.cx, camera.fy * yd + camera.cy};
}

CullingEvidence parse_culling_evidence(const std::string& text, const std::string& setting) {
  if (text == "off") return CullingEvidence::none;
  if (text == "mask") return CullingEvidence::dynamic_pixels;
  if (text == "seen-through") return CullingEvidence::seen_through;
  throw Error(setting + ": '" + text + "' is not a culling evidence (off, mask, seen-through)");
}

const std::vector<std::shared_ptr<MapPoint>>& DynamicPointCuller::observe(
    std::span<const std::shared_ptr<MapPoint>> points, const Pose& T_world_camera,
    const cv::Mat& dynamic_mask, const cv::Mat& depth, const PinholeCamera& camera) {
  to_cull_.clear();
  verdicts_.clear();
  if (params_.evidence == CullingEvidence::none) return to_cull_;
  const bool by_mask = params_.evidence == CullingEvidence::dynamic_pixels;
  if (depth.empty() || (by_mask && dynamic_mask.empty())) return to_cull_;
  const Pose T_camera_world = T_world_camera.inverse();
  int against = 0, measured = 0;
  for (const auto& point : points) {
    if (!point || point->is_bad()) continue;
    const auto projection = project(*point, T_camera_world, camera, depth);
    if (!projection) continue;
    const Verdict verdict = by_mask ? on_dynamic_pixels(*projection, dynamic_mask, depth)
                                    : seen_through(*projection, depth);
    if (verdict == Verdict::none) continue;
    against += verdict == Verdict::against;
    ++measured;
    verdicts_.emplace_back(point, verdict);
  }
  // Seeing through a large share of the map at once is a wrong pose, not a moved scene.
  if (!by_mask && measured >= params_.min_points_measured &&
      against > params_.max_seen_through_share * measured)
    return to_cull_;
  for (const auto& [point, verdict] : verdicts_) {
    if (verdict == Verdict::against) {
      count_against(point);
    } else if (!by_mask) {
      // Measured where the map has it: one frame's doubt is withdrawn.
      const auto it = hits_.find(point->id());
      if (it != hits_.end() && --it->second <= 0) hits_.erase(it);
    }
  }
  return to_cull_;
}

std::optional<DynamicPointCuller::Projection> DynamicPointCuller::project(
    const MapPoint& point, const Pose& T_camera_world, const PinholeCamera& camera,
    const cv::Mat& image) const {
  const Eigen::Vector3d p = T_camera_world * point.position();
  if (p.z() <= 0.0) return std::nullopt;
  // The depth image is as recorded; masks share its pixels (the mask rule reads both at the
  // ideal pinhole's pixel, as it was measured with).
  const Eigen::Vector2d pixel = params_.evidence == CullingEvidence::seen_through
                                    ? project_distorted(camera, p)
                                    : camera.project(p);
  const Projection projection{static_cast<int>(std::lround(pixel.x())),
                              static_cast<int>(std::lround(pixel.y())), p.z()};
  if (projection.u < 0 || projection.v < 0 || projection.u >= image.cols ||
      projection.v >= image.rows)
    return std::nullopt;
  return projection;
}

DynamicPointCuller::Verdict DynamicPointCuller::on_dynamic_pixels(const Projection& p,
                                                                  const cv::Mat& mask,
                                                                  const cv::Mat& depth) const {
  if (!mask.at<std::uint8_t>(p.v, p.u)) return Verdict::none;
  const float measured = depth.at<float>(p.v, p.u);
  if (measured <= 0.0f) return Verdict::none;
  const double tolerance =
      params_.depth_tolerance_abs_m + params_.depth_tolerance_relative * measured;
  // Occluded by the mover (measured in front of it) says nothing about the point.
  return std::abs(measured - p.z) <= tolerance ? Verdict::against : Verdict::none;
}

DynamicPointCuller::Verdict DynamicPointCuller::seen_through(const Projection& p,
                                                             const cv::Mat& depth) const {
  const float at_point = depth.at<float>(p.v, p.u);
  if (at_point <= 0.0f) return Verdict::none;
  const double tolerance =
      params_.depth_tolerance_abs_m + params_.depth_tolerance_relative * at_point;
  if (std::abs(at_point - p.z) <= tolerance) return Verdict::confirmed;
  if (at_point < p.z) return Verdict::none;  // occluded
  const double margin =
      params_.seen_through_margin_abs_m + params_.seen_through_margin_relative * at_point;
  if (at_point - p.z <= margin) return Verdict::none;
  const int r = params_.seen_through_radius_px;
  const int offsets[4][2] = {{-r, 0}, {r, 0}, {0, -r}, {0, r}};
  for (const auto& [du, dv] : offsets) {
    const int u = p.u + du, v = p.v + dv;
    if (u < 0 || v < 0 || u >= depth.cols || v >= depth.rows) return Verdict::none;
    const float around = depth.at<float>(v, u);
    // No reading, or a surface at or before the point: an edge, not free space.
    if (around <= 0.0f || around - p.z <= margin) return Verdict::none;
  }
  return Verdict::against;
}

void DynamicPointCuller::count_against(const std::shared_ptr<MapPoint>& point) {
  int& hits = hits_[point->id()];
  if (++hits >= params_.min_dynamic_hits) {
    to_cull_.push_back(point);
    hits_.erase(point->id());
  }
}

}  // namespace pspslam
