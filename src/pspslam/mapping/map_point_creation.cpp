#include "pspslam/mapping/map_point_creation.h"

#include <algorithm>
#include <cmath>

#include "pspslam/map/keyframe.h"
#include "pspslam/map/map.h"
#include "pspslam/map/map_point.h"
#include "pspslam/mapping/keyframe_matching.h"
#include "pspslam/solve/triangulation.h"

namespace pspslam {
namespace {

std::shared_ptr<MapPoint> make_point(
    Map& map, const Eigen::Vector3d& position,
    const std::vector<std::pair<std::shared_ptr<KeyFrame>, int>>& observations) {
  const auto& reference = observations.front().first;
  auto point = std::make_shared<MapPoint>(map.next_map_point_id(), position, reference);
  for (const auto& [keyframe, index] : observations) {
    point->add_observation(keyframe, index);
    keyframe->add_map_point(index, point);
  }
  point->compute_distinctive_descriptor();
  point->update_normal_and_depth(reference->pyramid());
  map.add_map_point(point);
  return point;
}

Eigen::Vector3d bearing_world(const KeyFrame& keyframe, int index, const Pose& T_world_camera) {
  const cv::Point2f& p = keyframe.keypoints()[index].pt;
  const PinholeCamera& pinhole = keyframe.camera().pinhole;
  const Eigen::Vector3d ray((p.x - pinhole.cx) / pinhole.fx, (p.y - pinhole.cy) / pinhole.fy, 1.0);
  return T_world_camera.linear() * ray;
}

Eigen::Vector2d normalised(const KeyFrame& keyframe, int index) {
  const cv::Point2f& p = keyframe.keypoints()[index].pt;
  const PinholeCamera& pinhole = keyframe.camera().pinhole;
  return {(p.x - pinhole.cx) / pinhole.fx, (p.y - pinhole.cy) / pinhole.fy};
}

bool reprojects(const KeyFrame& keyframe, int index, const Pose& T_camera_world,
                const Eigen::Vector3d& position) {
  const Eigen::Vector3d point_camera = T_camera_world * position;
  if (point_camera.z() <= 0.0) return false;
  const CameraModel& camera = keyframe.camera();
  const cv::KeyPoint& keypoint = keyframe.keypoints()[index];
  const Eigen::Vector2d pixel = camera.pinhole.project(point_camera);
  const double du = keypoint.pt.x - pixel.x();
  const double dv = keypoint.pt.y - pixel.y();
  const double sigma2 = keyframe.pyramid().sigma2[keypoint.octave];
  if (!keyframe.has_depth(index)) return du * du + dv * dv <= 5.991 * sigma2;
  const double dr = keyframe.right_u(index) - (pixel.x() - camera.bf / point_camera.z());
  return du * du + dv * dv + dr * dr <= 7.8 * sigma2;
}

// Parallax that a depth reading offers: the angle the virtual baseline subtends at that depth.
double depth_parallax_cos(const KeyFrame& keyframe, int index) {
  if (!keyframe.has_depth(index)) return 2.0;  // no depth: any ray parallax beats it
  return std::cos(2.0 * std::atan2(keyframe.camera().baseline() / 2.0, keyframe.depth(index)));
}

}  // namespace

std::vector<std::shared_ptr<MapPoint>> create_points_from_depth(
    Map& map, const std::shared_ptr<KeyFrame>& keyframe, const LocalMappingOptions& options) {
  const std::vector<std::shared_ptr<MapPoint>> existing = keyframe->map_points();
  std::vector<std::pair<float, int>> by_depth;
  for (int i = 0; i < keyframe->size(); ++i) {
    if (keyframe->depth(i) > 0.0f && !existing[i]) by_depth.emplace_back(keyframe->depth(i), i);
  }
  std::sort(by_depth.begin(), by_depth.end());
  std::vector<std::shared_ptr<MapPoint>> created;
  for (const auto& [depth, index] : by_depth) {
    if (depth > options.close_depth &&
        static_cast<int>(created.size()) >= options.min_depth_points) {
      break;
    }
    created.push_back(make_point(map, keyframe->unproject_world(index), {{keyframe, index}}));
  }
  return created;
}

std::vector<std::shared_ptr<MapPoint>> create_points_by_triangulation(
    Map& map, const std::shared_ptr<KeyFrame>& keyframe, const LocalMappingOptions& options,
    const std::function<bool()>& should_stop) {
  std::vector<std::shared_ptr<MapPoint>> created;
  const Pose T_cw1 = keyframe->T_camera_world();
  const Pose T_wc1 = T_cw1.inverse();
  const Eigen::Matrix<double, 3, 4> P1 = T_cw1.matrix().topRows<3>();
  const ScalePyramid& pyramid = keyframe->pyramid();
  const double scale_ratio_tolerance = 1.5 * pyramid.scale_factor;

  for (const auto& neighbour : keyframe->best_covisibles(options.triangulation_neighbours)) {
    if (should_stop && !created.empty() && should_stop()) break;
    const Pose T_cw2 = neighbour->T_camera_world();
    const Pose T_wc2 = T_cw2.inverse();
    // Below the virtual baseline the depth readings constrain the point better than the rays.
    if ((T_wc2.translation() - T_wc1.translation()).norm() < neighbour->camera().baseline()) {
      continue;
    }
    const Eigen::Matrix<double, 3, 4> P2 = T_cw2.matrix().topRows<3>();
    for (const KeypointMatch& match :
         search_for_triangulation(*keyframe, *neighbour, options.max_descriptor_distance)) {
      const int i1 = match.index1;
      const int i2 = match.index2;
      const Eigen::Vector3d ray1 = bearing_world(*keyframe, i1, T_wc1);
      const Eigen::Vector3d ray2 = bearing_world(*neighbour, i2, T_wc2);
      const double rays_cos = ray1.dot(ray2) / (ray1.norm() * ray2.norm());
      const double depth_cos1 = depth_parallax_cos(*keyframe, i1);
      const double depth_cos2 = depth_parallax_cos(*neighbour, i2);
      const double best_depth_cos = std::min(depth_cos1, depth_cos2);
      const bool has_depth = best_depth_cos <= 1.0;

      Eigen::Vector3d position;
      if (rays_cos < best_depth_cos && rays_cos > 0.0 && (has_depth || rays_cos < 0.9998)) {
        position = triangulate_dlt(normalised(*keyframe, i1), P1, normalised(*neighbour, i2), P2);
        if (!position.allFinite()) continue;
      } else if (depth_cos1 <= 1.0 && depth_cos1 <= depth_cos2) {
        position = keyframe->unproject_world(i1);
      } else if (depth_cos2 <= 1.0) {
        position = neighbour->unproject_world(i2);
      } else {
        continue;  // too little parallax and no depth
      }

      if (!reprojects(*keyframe, i1, T_cw1, position) ||
          !reprojects(*neighbour, i2, T_cw2, position)) {
        continue;
      }
      // Scale consistency: distances must scale like the keypoints' pyramid levels.
      const double distance1 = (position - T_wc1.translation()).norm();
      const double distance2 = (position - T_wc2.translation()).norm();
      if (distance1 <= 0.0 || distance2 <= 0.0) continue;
      const double distance_ratio = distance2 / distance1;
      const double octave_ratio = pyramid.scale[keyframe->keypoints()[i1].octave] /
                                  pyramid.scale[neighbour->keypoints()[i2].octave];
      if (distance_ratio * scale_ratio_tolerance < octave_ratio ||
          distance_ratio > octave_ratio * scale_ratio_tolerance) {
        continue;
      }
      created.push_back(make_point(map, position, {{keyframe, i1}, {neighbour, i2}}));
    }
  }
  return created;
}

}  // namespace pspslam
