#include "pspslam/mapping/keyframe_matching.h"

#include <Eigen/Core>
#include <climits>
#include <cmath>

#include "pspslam/core/types.h"
#include "pspslam/map/descriptor.h"
#include "pspslam/map/keyframe.h"
#include "pspslam/map/map.h"
#include "pspslam/map/map_point.h"

namespace pspslam {
namespace {

// F21 with x2ᵀ F21 x1 = 0 for pixels x1 in `first`, x2 in `second`.
Eigen::Matrix3d fundamental_matrix(const KeyFrame& first, const KeyFrame& second) {
  const Pose T_21 = second.T_camera_world() * first.T_world_camera();
  const Eigen::Matrix3d essential = skew_symmetric(T_21.translation()) * T_21.linear();
  const PinholeCamera& pinhole = first.camera().pinhole;
  Eigen::Matrix3d K_inv = Eigen::Matrix3d::Identity();
  K_inv(0, 0) = 1.0 / pinhole.fx;
  K_inv(1, 1) = 1.0 / pinhole.fy;
  K_inv(0, 2) = -pinhole.cx / pinhole.fx;
  K_inv(1, 2) = -pinhole.cy / pinhole.fy;
  return K_inv.transpose() * essential * K_inv;
}

// χ² (2 or 3 dof) of keypoint `index` of `keyframe` against a camera point, weighted by the
// level's information.
double keypoint_chi_squared(const KeyFrame& keyframe, int index,
                            const Eigen::Vector3d& point_camera) {
  const CameraModel& camera = keyframe.camera();
  const cv::KeyPoint& keypoint = keyframe.keypoints()[index];
  const Eigen::Vector2d projected = camera.pinhole.project(point_camera);
  const double du = keypoint.pt.x - projected.x();
  const double dv = keypoint.pt.y - projected.y();
  double squared = du * du + dv * dv;
  if (keyframe.has_depth(index)) {
    const double dr = keyframe.right_u(index) - (projected.x() - camera.bf / point_camera.z());
    squared += dr * dr;
  }
  return squared * keyframe.pyramid().inv_sigma2[keypoint.octave];
}

}  // namespace

std::vector<KeypointMatch> search_for_triangulation(const KeyFrame& first, const KeyFrame& second,
                                                    int max_descriptor_distance) {
  const Eigen::Matrix3d F21 = fundamental_matrix(first, second);
  // Epipole of the first camera in the second image: matches next to it are ill-conditioned.
  const Eigen::Vector3d center1_in_2 = second.T_camera_world() * first.camera_center();
  const PinholeCamera& pinhole = second.camera().pinhole;
  const Eigen::Vector2d epipole =
      center1_in_2.z() > 0.0 ? pinhole.project(center1_in_2) : Eigen::Vector2d(-1e9, -1e9);

  const std::vector<std::shared_ptr<MapPoint>> points1 = first.map_points();
  const std::vector<std::shared_ptr<MapPoint>> points2 = second.map_points();
  std::vector<int> free2;
  for (int i = 0; i < second.size(); ++i) {
    if (!points2[i]) free2.push_back(i);
  }
  std::vector<uint8_t> matched2(second.size(), 0);
  const std::vector<double>& sigma2 = second.pyramid().sigma2;
  const std::vector<double>& scale = second.pyramid().scale;

  std::vector<KeypointMatch> matches;
  for (int i1 = 0; i1 < first.size(); ++i1) {
    if (points1[i1]) continue;
    const cv::Point2f& p1 = first.keypoints()[i1].pt;
    const Eigen::Vector3d line = F21 * Eigen::Vector3d(p1.x, p1.y, 1.0);
    const double line_norm2 = line.x() * line.x() + line.y() * line.y();
    if (line_norm2 <= 0.0) continue;
    const bool depth1 = first.has_depth(i1);
    int best_distance = max_descriptor_distance + 1;
    int best_index = -1;
    for (const int i2 : free2) {
      if (matched2[i2]) continue;
      const cv::KeyPoint& keypoint2 = second.keypoints()[i2];
      const double distance_to_line =
          line.x() * keypoint2.pt.x + line.y() * keypoint2.pt.y + line.z();
      if (distance_to_line * distance_to_line >= 3.84 * sigma2[keypoint2.octave] * line_norm2) {
        continue;
      }
      if (!depth1 && !second.has_depth(i2)) {
        const double ex = epipole.x() - keypoint2.pt.x;
        const double ey = epipole.y() - keypoint2.pt.y;
        if (ex * ex + ey * ey < 100.0 * scale[keypoint2.octave]) continue;
      }
      const int distance = descriptor_distance(first.descriptor(i1), second.descriptor(i2));
      if (distance < best_distance) {
        best_distance = distance;
        best_index = i2;
      }
    }
    if (best_index >= 0) {
      matched2[best_index] = 1;
      matches.push_back({i1, best_index});
    }
  }
  return matches;
}

int fuse_into_keyframe(Map& map, const std::shared_ptr<KeyFrame>& keyframe,
                       const std::vector<std::shared_ptr<MapPoint>>& points, double radius,
                       int max_descriptor_distance) {
  const Pose T_cw = keyframe->T_camera_world();
  const Eigen::Vector3d center = keyframe->camera_center();
  const CameraModel& camera = keyframe->camera();
  const ScalePyramid& pyramid = keyframe->pyramid();
  std::vector<int> candidates;
  int fused = 0;
  for (const auto& point : points) {
    if (!point || point->is_bad() || point->is_observed_by(keyframe->id())) continue;
    const Eigen::Vector3d position = point->position();
    const Eigen::Vector3d point_camera = T_cw * position;
    if (point_camera.z() <= 0.0) continue;
    const Eigen::Vector2d pixel = camera.pinhole.project(point_camera);
    if (!camera.in_bounds(pixel.x(), pixel.y())) continue;
    const Eigen::Vector3d ray = position - center;
    const double distance = ray.norm();
    if (distance < point->min_distance() || distance > point->max_distance()) continue;
    if (ray.dot(point->normal()) < 0.5 * distance) continue;  // viewed > 60° off its normal
    const int level = point->predict_level(distance, pyramid);
    keyframe->features_in_area(pixel.x(), pixel.y(), radius * pyramid.scale[level], level - 1,
                               level, candidates);
    const OrbDescriptor descriptor = point->descriptor();
    int best_distance = INT_MAX;
    int best_index = -1;
    for (const int index : candidates) {
      const double threshold = keyframe->has_depth(index) ? 7.8 : 5.99;
      if (keypoint_chi_squared(*keyframe, index, point_camera) > threshold) continue;
      const int d = descriptor_distance(descriptor, keyframe->descriptor(index));
      if (d < best_distance) {
        best_distance = d;
        best_index = index;
      }
    }
    if (best_index < 0 || best_distance > max_descriptor_distance) continue;
    if (const auto existing = keyframe->map_point(best_index)) {
      // Keep the better-established point; the other one is merged into it and erased.
      const bool keep_existing = existing->num_observations() > point->num_observations();
      const auto& keep = keep_existing ? existing : point;
      const auto& drop = keep_existing ? point : existing;
      if (drop->replace_with(keep)) map.erase_map_point(drop);
    } else {
      point->add_observation(keyframe, best_index);
      keyframe->add_map_point(best_index, point);
    }
    ++fused;
  }
  return fused;
}

}  // namespace pspslam
