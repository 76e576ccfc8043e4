#include "mapping/synthetic_world.h"

#include <numbers>

#include "pspslam/map/frame.h"

namespace pspslam::testing {

SyntheticWorld::SyntheticWorld(int num_points, double no_depth_fraction, uint32_t seed)
    : rng_(seed) {
  camera_ = std::make_shared<const CameraModel>(CameraModel::from_config(CameraConfig{}, 0.08));
  pyramid_ = std::make_shared<const ScalePyramid>(ScalePyramid::from_config(OrbConfig{}));
  std::uniform_real_distribution<double> x(-2.5, 3.5), y(-1.5, 1.5), z(1.5, 5.0);
  std::bernoulli_distribution no_depth(no_depth_fraction);
  for (int i = 0; i < num_points; ++i) {
    WorldPoint point;
    point.position = {x(rng_), y(rng_), z(rng_)};
    point.descriptor = cv::Mat(1, 32, CV_8U);
    cv::randu(point.descriptor, 0, 256);
    point.has_depth = !no_depth(rng_);
    points_.push_back(point);
  }
}

int SyntheticWorld::add_transient_point(const Eigen::Vector3d& position,
                                        std::uint64_t keyframe_id) {
  WorldPoint point;
  point.position = position;
  point.descriptor = cv::Mat(1, 32, CV_8U);
  cv::randu(point.descriptor, 0, 256);
  point.only_in_keyframe = static_cast<std::int64_t>(keyframe_id);
  points_.push_back(point);
  return static_cast<int>(points_.size()) - 1;
}

std::shared_ptr<KeyFrame> SyntheticWorld::make_keyframe(std::uint64_t id,
                                                        const Pose& T_camera_world_true,
                                                        const Pose& estimated_T_camera_world,
                                                        const Map& map,
                                                        double wrong_association_fraction) {
  const PinholeCamera& pinhole = camera_->pinhole;
  cv::Mat depth(pinhole.height, pinhole.width, CV_32F, cv::Scalar(0.0f));
  cv::Mat occupied(pinhole.height, pinhole.width, CV_8U, cv::Scalar(0));
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  std::vector<int> keypoint_world;
  std::normal_distribution<double> noise(0.0, 1.0);
  std::uniform_real_distribution<float> angle(0.0f, 360.0f);
  for (int i = 0; i < static_cast<int>(points_.size()); ++i) {
    if (points_[i].only_in_keyframe >= 0 &&
        points_[i].only_in_keyframe != static_cast<std::int64_t>(id)) {
      continue;
    }
    const Eigen::Vector3d point_camera = T_camera_world_true * points_[i].position;
    if (point_camera.z() < 0.3) continue;
    const Eigen::Vector2d ideal = pinhole.project(point_camera);
    if (!pinhole.in_image(ideal, 8.0)) continue;
    const int u = static_cast<int>(std::lround(ideal.x()));
    const int v = static_cast<int>(std::lround(ideal.y()));
    if (occupied.at<uint8_t>(v, u)) continue;  // two points on one pixel: keep the first
    occupied.at<uint8_t>(v, u) = 1;
    // Noise keeps the keypoint on its depth pixel (the frame reads depth at the rounded pixel).
    const double dx = std::clamp(noise(rng_), -0.45, 0.45);
    const double dy = std::clamp(noise(rng_), -0.45, 0.45);
    cv::KeyPoint keypoint(static_cast<float>(u + dx), static_cast<float>(v + dy), 31.0f,
                          angle(rng_), 1.0f, 0);
    keypoints.push_back(keypoint);
    descriptors.push_back(points_[i].descriptor);
    keypoint_world.push_back(i);
    if (points_[i].has_depth) depth.at<float>(v, u) = static_cast<float>(point_camera.z());
  }

  Frame frame(id, static_cast<double>(id), keypoints, descriptors, depth, camera_, pyramid_);
  frame.set_pose(estimated_T_camera_world);
  // "Tracking": associate keypoints with the map points standing for the same world point.
  std::map<int, std::shared_ptr<MapPoint>> by_world;
  for (const auto& point : map.map_points()) {
    if (point->is_bad()) continue;
    const int w = world_index(*point);
    if (w >= 0) by_world.emplace(w, point);
  }
  std::vector<std::shared_ptr<MapPoint>> all_points;
  for (const auto& [w, point] : by_world) all_points.push_back(point);
  std::bernoulli_distribution wrong(wrong_association_fraction);
  for (size_t k = 0; k < keypoint_world.size(); ++k) {
    const auto found = by_world.find(keypoint_world[k]);
    if (found == by_world.end()) continue;
    frame.map_points[k] = found->second;
    if (wrong(rng_)) {
      std::uniform_int_distribution<size_t> any(0, all_points.size() - 1);
      frame.map_points[k] = all_points[any(rng_)];
    }
  }
  keypoint_world_index_[id] = keypoint_world;
  return std::make_shared<KeyFrame>(id, frame);
}

int SyntheticWorld::world_index(std::uint64_t keyframe_id, int index) const {
  const auto found = keypoint_world_index_.find(keyframe_id);
  if (found == keypoint_world_index_.end() || index < 0 ||
      index >= static_cast<int>(found->second.size())) {
    return -1;
  }
  return found->second[index];
}

int SyntheticWorld::world_index(const MapPoint& point) const {
  for (const auto& [keyframe_id, observation] : point.observations()) {
    const int w = world_index(keyframe_id, observation.keypoint_index);
    if (w >= 0) return w;
  }
  return -1;
}

Pose path_pose(int k, double step_metres, double yaw_step) {
  Pose T_world_camera = Pose::Identity();
  T_world_camera.linear() =
      Eigen::AngleAxisd(yaw_step * k, Eigen::Vector3d::UnitY()).toRotationMatrix();
  T_world_camera.translation() = Eigen::Vector3d(step_metres * k, 0.02 * k, 0.0);
  return T_world_camera.inverse();
}

Pose perturbed(const Pose& pose, double angle_rad, double translation_m, std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Pose delta = Pose::Identity();
  delta.linear() =
      Eigen::AngleAxisd(angle_rad,
                        Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized())
          .toRotationMatrix();
  delta.translation() =
      translation_m * Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
  return delta * pose;
}

double rotation_error_deg(const Pose& a, const Pose& b) {
  return Eigen::AngleAxisd(a.linear() * b.linear().transpose()).angle() * 180.0 / std::numbers::pi;
}

double center_error(const Pose& T_camera_world_a, const Pose& T_camera_world_b) {
  return (T_camera_world_a.inverse().translation() - T_camera_world_b.inverse().translation())
      .norm();
}

}  // namespace pspslam::testing
