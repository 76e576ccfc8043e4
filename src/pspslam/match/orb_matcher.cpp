#include "pspslam/match/orb_matcher.h"

#include <algorithm>
#include <climits>
#include <cmath>

#include "pspslam/map/descriptor.h"
#include "pspslam/map/frame.h"
#include "pspslam/map/keyframe.h"
#include "pspslam/map/map_point.h"

namespace pspslam {
namespace {

// Search radius for a point seen with view_cos: a point seen head-on is predicted more reliably.
double radius_by_viewing_cos(double view_cos) { return view_cos > 0.998 ? 2.5 : 4.0; }

// Best and second-best distance of a descriptor against candidate keypoints of a frame that
// have no map point yet, restricted to the virtual-stereo consistency of the right coordinate.
struct BestTwo {
  int best_distance = INT_MAX;
  int second_distance = INT_MAX;
  int best_index = -1;
  int best_level = -1;
  int second_level = -1;
};

}  // namespace

bool project_map_point(const std::shared_ptr<MapPoint>& point, const Frame& frame,
                       ProjectedPoint& out) {
  const Eigen::Vector3d position = point->position();
  const Pose& T_cw = frame.T_camera_world();
  const Eigen::Vector3d p_camera = T_cw * position;
  if (p_camera.z() <= 0.0) return false;
  const CameraModel& camera = frame.camera();
  const Eigen::Vector2d pixel = camera.pinhole.project(p_camera);
  if (!camera.in_bounds(pixel.x(), pixel.y())) return false;
  const Eigen::Vector3d ray = position - T_cw.inverse().translation();
  const double distance = ray.norm();
  if (distance < point->min_distance() || distance > point->max_distance()) return false;
  const double view_cos = ray.dot(point->normal()) / distance;
  // 60 degrees: beyond it the descriptor has changed too much to match reliably.
  if (view_cos < 0.5) return false;
  out.point = point;
  out.u = pixel.x();
  out.v = pixel.y();
  out.right_u = pixel.x() - camera.bf / p_camera.z();
  out.predicted_level = point->predict_level(distance, frame.pyramid());
  out.view_cos = view_cos;
  return true;
}

void RotationHistogram::clear() {
  for (auto& bin : bins_) bin.clear();
}

void RotationHistogram::add(float angle_from_degrees, float angle_to_degrees, int match_index) {
  float diff = angle_from_degrees - angle_to_degrees;
  if (diff < 0.0f) diff += 360.0f;
  int bin = static_cast<int>(std::lround(diff * kBins / 360.0f));
  if (bin == kBins) bin = 0;
  bins_[bin].push_back(match_index);
}

std::vector<int> RotationHistogram::rejected() const {
  // The three largest bins (ORB-SLAM2 ComputeThreeMaxima): a bin below 10% of the largest
  // is dropped even if it ranks second or third.
  std::array<int, 3> top{-1, -1, -1};
  auto size_of = [&](int b) { return b < 0 ? 0 : static_cast<int>(bins_[b].size()); };
  for (int b = 0; b < kBins; ++b) {
    const int s = static_cast<int>(bins_[b].size());
    if (s > size_of(top[0])) {
      top = {b, top[0], top[1]};
    } else if (s > size_of(top[1])) {
      top = {top[0], b, top[1]};
    } else if (s > size_of(top[2])) {
      top[2] = b;
    }
  }
  const int largest = size_of(top[0]);
  if (size_of(top[1]) < 0.1 * largest) top[1] = -1;
  if (size_of(top[2]) < 0.1 * largest) top[2] = -1;
  std::vector<int> out;
  for (int b = 0; b < kBins; ++b) {
    if (b == top[0] || b == top[1] || b == top[2]) continue;
    out.insert(out.end(), bins_[b].begin(), bins_[b].end());
  }
  return out;
}

int search_by_projection(Frame& frame, const std::vector<ProjectedPoint>& projected,
                         double radius_scale, const MatcherOptions& options) {
  int matches = 0;
  std::vector<int> candidates;
  candidates.reserve(64);
  const ScalePyramid& pyramid = frame.pyramid();
  for (const ProjectedPoint& p : projected) {
    if (p.point->is_bad()) continue;
    const int level = p.predicted_level;
    const double radius = radius_by_viewing_cos(p.view_cos) * radius_scale * pyramid.scale[level];
    frame.features_in_area(p.u, p.v, radius, level - 1, level, candidates);
    if (candidates.empty()) continue;
    const OrbDescriptor descriptor = p.point->descriptor();
    BestTwo best;
    for (int i : candidates) {
      if (frame.map_points[i] && frame.map_points[i]->num_observations() > 0) continue;
      // With depth, the virtual right coordinate must agree too (ORB-SLAM2 stereo check).
      if (frame.has_depth(i)) {
        const double error = std::abs(p.right_u - frame.right_u(i));
        if (error > radius * pyramid.scale[level]) continue;
      }
      const int distance = descriptor_distance(descriptor, frame.descriptor(i));
      const int kp_level = frame.keypoints()[i].octave;
      if (distance < best.best_distance) {
        best.second_distance = best.best_distance;
        best.second_level = best.best_level;
        best.best_distance = distance;
        best.best_level = kp_level;
        best.best_index = i;
      } else if (distance < best.second_distance) {
        best.second_distance = distance;
        best.second_level = kp_level;
      }
    }
    if (best.best_distance > options.max_distance_loose) continue;
    // Ratio test only between candidates of the same level (different levels are different
    // evidence, as ORB-SLAM2 does).
    if (best.best_level == best.second_level &&
        best.best_distance > options.nn_ratio * best.second_distance) {
      continue;
    }
    frame.map_points[best.best_index] = p.point;
    frame.outlier[best.best_index] = 0;
    ++matches;
  }
  return matches;
}

int search_previous_frame(Frame& current, const Frame& previous, double radius,
                          const MatcherOptions& options) {
  const Pose& T_cw = current.T_camera_world();
  const ScalePyramid& pyramid = current.pyramid();
  const CameraModel& camera = current.camera();
  // Camera moving forward / backward along its axis shifts the expected scale of features.
  const Eigen::Vector3d t_last_current =
      previous.T_camera_world() * current.T_camera_world().inverse().translation();
  const bool forward = t_last_current.z() > camera.baseline();
  const bool backward = -t_last_current.z() > camera.baseline();

  RotationHistogram histogram;
  std::vector<int> matched_index;  // per match: current keypoint index
  std::vector<int> candidates;
  candidates.reserve(64);
  int matches = 0;
  for (int j = 0; j < previous.size(); ++j) {
    const std::shared_ptr<MapPoint>& point = previous.map_points[j];
    if (!point || previous.outlier[j] || point->is_bad()) continue;
    const Eigen::Vector3d p_camera = T_cw * point->position();
    if (p_camera.z() <= 0.0) continue;
    const Eigen::Vector2d pixel = camera.pinhole.project(p_camera);
    if (!camera.in_bounds(pixel.x(), pixel.y())) continue;
    const int last_level = previous.keypoints()[j].octave;
    const double window = radius * pyramid.scale[last_level];
    if (forward) {
      current.features_in_area(pixel.x(), pixel.y(), window, last_level, -1, candidates);
    } else if (backward) {
      current.features_in_area(pixel.x(), pixel.y(), window, 0, last_level, candidates);
    } else {
      current.features_in_area(pixel.x(), pixel.y(), window, last_level - 1, last_level + 1,
                               candidates);
    }
    if (candidates.empty()) continue;
    const std::uint8_t* descriptor = previous.descriptor(j);
    const double right_u = pixel.x() - camera.bf / p_camera.z();
    int best_distance = INT_MAX;
    int best_index = -1;
    for (int i : candidates) {
      if (current.map_points[i] && current.map_points[i]->num_observations() > 0) continue;
      if (current.has_depth(i) && std::abs(right_u - current.right_u(i)) > window) continue;
      const int distance = descriptor_distance(descriptor, current.descriptor(i));
      if (distance < best_distance) {
        best_distance = distance;
        best_index = i;
      }
    }
    if (best_distance > options.max_distance_loose) continue;
    current.map_points[best_index] = point;
    current.outlier[best_index] = 0;
    if (options.check_orientation) {
      histogram.add(previous.keypoints()[j].angle, current.keypoints()[best_index].angle,
                    static_cast<int>(matched_index.size()));
      matched_index.push_back(best_index);
    }
    ++matches;
  }
  if (options.check_orientation) {
    for (int m : histogram.rejected()) {
      current.map_points[matched_index[m]] = nullptr;
      --matches;
    }
  }
  return matches;
}

int search_keyframe_brute_force(Frame& frame, const KeyFrame& keyframe,
                                const MatcherOptions& options) {
  const std::vector<std::shared_ptr<MapPoint>> points = keyframe.map_points();
  // Best frame keypoint per keyframe keypoint, then keep the frame side one-to-one.
  std::vector<int> best_for_frame(frame.size(), -1);
  std::vector<int> distance_for_frame(frame.size(), INT_MAX);
  for (int k = 0; k < keyframe.size(); ++k) {
    if (!points[k]) continue;
    const std::uint8_t* descriptor = keyframe.descriptor(k);
    int best = INT_MAX;
    int second = INT_MAX;
    int best_index = -1;
    for (int i = 0; i < frame.size(); ++i) {
      const int distance = descriptor_distance(descriptor, frame.descriptor(i));
      if (distance < best) {
        second = best;
        best = distance;
        best_index = i;
      } else if (distance < second) {
        second = distance;
      }
    }
    if (best > options.max_distance_strict) continue;
    if (best > options.nn_ratio * second) continue;
    if (best < distance_for_frame[best_index]) {
      distance_for_frame[best_index] = best;
      best_for_frame[best_index] = k;
    }
  }
  RotationHistogram histogram;
  std::vector<int> matched_index;
  int matches = 0;
  for (int i = 0; i < frame.size(); ++i) {
    const int k = best_for_frame[i];
    if (k < 0) continue;
    frame.map_points[i] = points[k];
    frame.outlier[i] = 0;
    if (options.check_orientation) {
      histogram.add(keyframe.keypoints()[k].angle, frame.keypoints()[i].angle,
                    static_cast<int>(matched_index.size()));
      matched_index.push_back(i);
    }
    ++matches;
  }
  if (options.check_orientation) {
    for (int m : histogram.rejected()) {
      frame.map_points[matched_index[m]] = nullptr;
      --matches;
    }
  }
  return matches;
}

}  // namespace pspslam
