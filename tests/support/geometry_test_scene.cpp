#include "support/geometry_test_scene.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <random>

namespace pspslam {
namespace {

// Slab test; returns the entry distance (or the exit distance when the ray starts inside).
bool intersect_box(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                   const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double& t_hit) {
  double t_near = -std::numeric_limits<double>::infinity();
  double t_far = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (std::abs(direction[a]) < 1e-12) {
      if (origin[a] < lo[a] || origin[a] > hi[a]) return false;
      continue;
    }
    double t0 = (lo[a] - origin[a]) / direction[a];
    double t1 = (hi[a] - origin[a]) / direction[a];
    if (t0 > t1) std::swap(t0, t1);
    t_near = std::max(t_near, t0);
    t_far = std::min(t_far, t1);
  }
  if (t_near > t_far || t_far <= 0.0) return false;
  t_hit = t_near > 0.0 ? t_near : t_far;
  return true;
}

}  // namespace

GeometryTestScene::GeometryTestScene(GeometryTestSceneParams params) : params_(params) {
  std::mt19937_64 rng(params_.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  // World: x right, y down (floor at y = 1.2), z forward; the camera starts near the origin.
  // Static furniture gives depth edges and occlusions that a static point must survive.
  boxes_.push_back({{-1.6, 0.8, 3.5}, {0.5, 0.4, 0.4}, 0, 0, 0, 0});   // table
  boxes_.push_back({{1.9, 0.0, 4.2}, {0.4, 1.2, 0.3}, 0, 0, 0, 0});    // cabinet
  boxes_.push_back({{0.3, 1.0, 2.2}, {0.25, 0.2, 0.25}, 0, 0, 0, 0});  // crate on the floor
  for (int p = 0; p < params_.people; ++p) {
    const double depth = 2.0 + 1.5 * unit(rng);
    // Walking back and forth across the view (the field of view is ~+-1.3 m wide at 2.5 m).
    const double amplitude = 0.4 + 0.4 * unit(rng);
    const double omega = params_.person_speed_mps / amplitude;
    const double phase = 2.0 * M_PI * unit(rng);
    const double x0 = -0.5 + 1.0 * unit(rng);
    boxes_.push_back({{x0, 0.35, depth}, {0.22, 0.85, 0.15}, 15, amplitude, omega, phase});
    if (params_.carried_object && p == 0) {
      // Held at the side at hand height, moving with the person.
      boxes_.push_back(
          {{x0 + 0.38, 0.3, depth - 0.1}, {0.15, 0.15, 0.15}, 100, amplitude, omega, phase});
    }
  }
}

Eigen::Vector3d GeometryTestScene::box_center(const Box& box, double time) const {
  Eigen::Vector3d c = box.center;
  if (box.amplitude > 0.0) c.x() += box.amplitude * std::sin(box.omega * time + box.phase);
  return c;
}

Pose GeometryTestScene::camera_pose(int frame) const {
  const double t = frame / params_.fps;
  Pose T = Pose::Identity();
  // Hand-held-like motion: slow translation and a few degrees of yaw/pitch.
  T.translation() = Eigen::Vector3d(0.4 * std::sin(0.35 * t), -0.05 * std::sin(0.9 * t),
                                    -0.6 + 0.15 * std::sin(0.25 * t));
  T.linear() = (Eigen::AngleAxisd(0.12 * std::sin(0.4 * t), Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(0.04 * std::sin(0.7 * t), Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  return T;
}

void GeometryTestScene::render(int frame, cv::Mat& depth, cv::Mat& labels) const {
  const PinholeCamera& cam = params_.camera;
  const double time = frame / params_.fps;
  const Pose T_world_camera = camera_pose(frame);
  const Eigen::Matrix3d R = T_world_camera.linear();
  const Eigen::Vector3d origin = T_world_camera.translation();
  const Eigen::Vector3d room_lo(-3.0, -1.6, -2.0), room_hi(3.0, 1.2, 6.0);
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> extents;
  for (const Box& box : boxes_) {
    const Eigen::Vector3d c = box_center(box, time);
    extents.emplace_back(c - box.half_size, c + box.half_size);
  }
  depth.create(cam.height, cam.width, CV_32FC1);
  labels.create(cam.height, cam.width, CV_8UC1);
  std::mt19937_64 rng(params_.seed * 1000003ULL + static_cast<std::uint64_t>(frame));
  std::normal_distribution<double> noise(0.0, 1.0);
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      const Eigen::Vector3d ray_camera((u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy, 1.0);
      const Eigen::Vector3d direction = R * ray_camera;  // t along it = camera z depth
      double best = std::numeric_limits<double>::infinity();
      std::uint8_t label = 0;
      double t = 0.0;
      if (intersect_box(origin, direction, room_lo, room_hi, t)) best = t;
      for (size_t b = 0; b < boxes_.size(); ++b) {
        if (intersect_box(origin, direction, extents[b].first, extents[b].second, t) && t < best) {
          best = t;
          label = boxes_[b].label;
        }
      }
      float z = 0.0f;
      if (std::isfinite(best) && best < 10.0) {
        // Kinect axial noise model (Nguyen et al. 2012), then TUM quantisation (1/5000 m).
        const double sigma =
            params_.depth_noise_scale * (0.0012 + 0.0019 * (best - 0.4) * (best - 0.4));
        const double noisy = best + sigma * noise(rng);
        z = static_cast<float>(std::round(noisy * 5000.0) / 5000.0);
      }
      depth.at<float>(v, u) = z;
      labels.at<std::uint8_t>(v, u) = label;
    }
  }
}

std::vector<Eigen::Vector2d> sample_candidate_pixels(const cv::Mat& depth, int count,
                                                     std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  cv::Mat grad_x, grad_y, magnitude;
  cv::Sobel(depth, grad_x, CV_32F, 1, 0, 3);
  cv::Sobel(depth, grad_y, CV_32F, 0, 1, 3);
  cv::magnitude(grad_x, grad_y, magnitude);
  std::vector<Eigen::Vector2d> edges, all;
  for (int v = 2; v < depth.rows - 2; ++v) {
    for (int u = 2; u < depth.cols - 2; ++u) {
      if (!(depth.at<float>(v, u) > 0.0f)) continue;
      all.emplace_back(u, v);
      if (magnitude.at<float>(v, u) > 0.8f) edges.emplace_back(u, v);
    }
  }
  std::vector<Eigen::Vector2d> out;
  if (all.empty()) return out;
  std::uniform_int_distribution<size_t> pick_all(0, all.size() - 1);
  const int from_edges = edges.empty() ? 0 : count / 2;
  for (int i = 0; i < count - from_edges; ++i) out.push_back(all[pick_all(rng)]);
  if (from_edges > 0) {
    std::uniform_int_distribution<size_t> pick_edge(0, edges.size() - 1);
    for (int i = 0; i < from_edges; ++i) out.push_back(edges[pick_edge(rng)]);
  }
  return out;
}

}  // namespace pspslam
