#pragma once

// Synthetic scenes shared by the optimiser tests: a pinhole camera, random points in view, noisy
// RGB-D measurements (u, v, u_r) and pose perturbations / error metrics.

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <random>

#include "pspslam/camera/pinhole_camera.h"
#include "pspslam/core/types.h"

namespace pspslam::testing {

inline constexpr double kBaseline = 0.08;  // virtual RGB-D baseline, metres
inline constexpr double kScaleFactor = 1.2;

inline PinholeCamera test_camera() { return PinholeCamera{}; }  // 640×480, f = 525
inline double test_bf(const PinholeCamera& camera) { return camera.fx * kBaseline; }

inline double degrees(double radians) { return radians * 180.0 / std::numbers::pi; }
inline double radians(double degrees) { return degrees * std::numbers::pi / 180.0; }

inline Pose make_pose(const Eigen::Vector3d& axis_angle, const Eigen::Vector3d& translation) {
  Pose pose = Pose::Identity();
  const double angle = axis_angle.norm();
  if (angle > 0.0) pose.linear() = Eigen::AngleAxisd(angle, axis_angle / angle).toRotationMatrix();
  pose.translation() = translation;
  return pose;
}

// A rotation of exactly angle_deg about a random axis and a translation of exactly
// translation_m in a random direction, composed on the left.
inline Pose perturb(const Pose& pose, double angle_deg, double translation_m, std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  const Eigen::Vector3d axis = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
  const Eigen::Vector3d direction =
      Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
  return make_pose(radians(angle_deg) * axis, translation_m * direction) * pose;
}

inline double rotation_error_deg(const Pose& a, const Pose& b) {
  return degrees(Eigen::AngleAxisd(a.linear() * b.linear().transpose()).angle());
}

// Distance between the camera centres, metres.
inline double translation_error(const Pose& T_camera_world_a, const Pose& T_camera_world_b) {
  return (T_camera_world_a.inverse().translation() - T_camera_world_b.inverse().translation())
      .norm();
}

// A world point that the camera sees at a random pixel with a depth in [min_depth, max_depth].
inline Eigen::Vector3d random_visible_point(const PinholeCamera& camera, const Pose& T_camera_world,
                                            double min_depth, double max_depth, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(20.0, camera.width - 20.0);
  std::uniform_real_distribution<double> v(20.0, camera.height - 20.0);
  std::uniform_real_distribution<double> depth(min_depth, max_depth);
  const Eigen::Vector3d point_camera = camera.unproject({u(rng), v(rng)}, depth(rng));
  return T_camera_world.inverse() * point_camera;
}

struct NoisyMeasurement {
  Eigen::Vector2d pixel;
  double right_u;      // NaN without depth
  double information;  // 1 / σ² of the level
};

// Measures a point at a random pyramid level in [0, max_level]: noise σ = noise_px · scale^level
// on u, v and u_r, information = 1 / (scale^level)², exactly as the optimisers assume.
inline NoisyMeasurement measure(const PinholeCamera& camera, double bf, const Pose& T_camera_world,
                                const Eigen::Vector3d& point_world, bool with_depth,
                                double noise_px, int max_level, std::mt19937& rng) {
  std::uniform_int_distribution<int> level_distribution(0, max_level);
  const double scale = std::pow(kScaleFactor, level_distribution(rng));
  std::normal_distribution<double> noise(0.0, noise_px * scale);
  const Eigen::Vector3d point_camera = T_camera_world * point_world;
  const Eigen::Vector2d pixel = camera.project(point_camera);
  NoisyMeasurement measurement;
  measurement.pixel = pixel + Eigen::Vector2d(noise(rng), noise(rng));
  measurement.right_u = with_depth ? pixel.x() - bf / point_camera.z() + noise(rng)
                                   : std::numeric_limits<double>::quiet_NaN();
  measurement.information = 1.0 / (scale * scale);
  return measurement;
}

}  // namespace pspslam::testing
