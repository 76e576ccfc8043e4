#include "pspslam/loop/loop_matching.h"

#include <climits>
#include <unordered_set>

#include "pspslam/map/descriptor.h"
#include "pspslam/map/keyframe.h"
#include "pspslam/map/map_point.h"
#include "pspslam/match/orb_matcher.h"

namespace pspslam {
namespace {

struct Prediction {
  double u = 0.0;
  double v = 0.0;
  int level = 0;
};

// ORB-SLAM2's visibility test for a point placed in a camera: in front, inside the image,
// within the point's scale-invariance distances and less than 60° off its mean viewing
// direction. `center` is the camera centre in the same world frame as `position`.
bool predict(const KeyFrame& keyframe, const Pose& T_camera_world, const Eigen::Vector3d& center,
             const MapPoint& point, const Eigen::Vector3d& position, Prediction& out) {
  const Eigen::Vector3d point_camera = T_camera_world * position;
  if (point_camera.z() <= 0.0) return false;
  const CameraModel& camera = keyframe.camera();
  const Eigen::Vector2d pixel = camera.pinhole.project(point_camera);
  if (!camera.in_bounds(pixel.x(), pixel.y())) return false;
  const Eigen::Vector3d ray = position - center;
  const double distance = ray.norm();
  if (distance < point.min_distance() || distance > point.max_distance()) return false;
  if (ray.dot(point.normal()) < 0.5 * distance) return false;
  out.u = pixel.x();
  out.v = pixel.y();
  out.level = point.predict_level(distance, keyframe.pyramid());
  return true;
}

// The unmatched keypoint nearest in descriptor to `descriptor` around a prediction; -1 if none
// within max_distance.
int best_in_area(const KeyFrame& keyframe, const Prediction& prediction, double radius,
                 const OrbDescriptor& descriptor, int max_distance,
                 const std::vector<std::shared_ptr<MapPoint>>& matched, std::vector<int>& area) {
  const ScalePyramid& pyramid = keyframe.pyramid();
  keyframe.features_in_area(prediction.u, prediction.v, radius * pyramid.scale[prediction.level],
                            prediction.level - 1, prediction.level + 1, area);
  int best_distance = INT_MAX;
  int best_index = -1;
  for (const int index : area) {
    if (matched[index]) continue;
    const int d = descriptor_distance(descriptor, keyframe.descriptor(index));
    if (d < best_distance) {
      best_distance = d;
      best_index = index;
    }
  }
  return best_distance <= max_distance ? best_index : -1;
}

void drop_inconsistent_rotations(const KeyFrame& keyframe, const KeyFrame& candidate,
                                 const std::vector<std::pair<int, int>>& pairs,
                                 std::vector<std::shared_ptr<MapPoint>>& matched) {
  RotationHistogram histogram;
  for (size_t m = 0; m < pairs.size(); ++m) {
    histogram.add(keyframe.keypoints()[pairs[m].first].angle,
                  candidate.keypoints()[pairs[m].second].angle, static_cast<int>(m));
  }
  for (const int m : histogram.rejected()) matched[pairs[m].first] = nullptr;
}

}  // namespace

int match_by_descriptor(const KeyFrame& keyframe, const KeyFrame& candidate,
                        std::vector<std::shared_ptr<MapPoint>>& matched,
                        const LoopMatchingOptions& options) {
  const auto own_points = keyframe.map_points();
  const auto candidate_points = candidate.map_points();
  // Best keypoint of `keyframe` per candidate keypoint so far (one-to-one).
  std::vector<int> taken_by(candidate_points.size(), -1);
  std::vector<int> taken_distance(candidate_points.size(), INT_MAX);
  const auto consider = [&](int i, const std::vector<int>& others) {
    if (!own_points[i] || matched[i]) return;
    int best = INT_MAX;
    int second = INT_MAX;
    int best_index = -1;
    for (const int j : others) {
      if (!candidate_points[j]) continue;
      const int d = descriptor_distance(keyframe.descriptor(i), candidate.descriptor(j));
      if (d < best) {
        second = best;
        best = d;
        best_index = j;
      } else if (d < second) {
        second = d;
      }
    }
    if (best_index < 0 || best > options.max_distance_strict) return;
    if (static_cast<double>(best) >= options.nn_ratio * static_cast<double>(second)) return;
    if (best >= taken_distance[best_index]) return;
    if (taken_by[best_index] >= 0) matched[taken_by[best_index]] = nullptr;
    taken_by[best_index] = i;
    taken_distance[best_index] = best;
    matched[i] = candidate_points[best_index];
  };

  const auto& own_features = keyframe.feature_vector();
  const auto& candidate_features = candidate.feature_vector();
  if (!own_features.empty() && !candidate_features.empty()) {
    // Walk both direct indexes in node order: only descriptors under one node are compared.
    size_t a = 0;
    size_t b = 0;
    std::vector<int> others;
    while (a < own_features.node_count() && b < candidate_features.node_count()) {
      const auto node_a = own_features.nodes()[a];
      const auto node_b = candidate_features.nodes()[b];
      if (node_a < node_b) {
        ++a;
      } else if (node_b < node_a) {
        ++b;
      } else {
        const auto candidate_span = candidate_features.features(b);
        others.assign(candidate_span.begin(), candidate_span.end());
        for (const int i : own_features.features(a)) consider(i, others);
        ++a;
        ++b;
      }
    }
  } else {
    std::vector<int> all(candidate_points.size());
    for (size_t j = 0; j < all.size(); ++j) all[j] = static_cast<int>(j);
    for (int i = 0; i < keyframe.size(); ++i) consider(i, all);
  }

  std::vector<std::pair<int, int>> pairs;
  for (size_t j = 0; j < taken_by.size(); ++j) {
    if (taken_by[j] >= 0 && matched[taken_by[j]] == candidate_points[j]) {
      pairs.emplace_back(taken_by[j], static_cast<int>(j));
    }
  }
  if (options.check_orientation) drop_inconsistent_rotations(keyframe, candidate, pairs, matched);
  int count = 0;
  for (const auto& [i, j] : pairs) count += matched[i] ? 1 : 0;
  return count;
}

int match_by_transform(const KeyFrame& keyframe, const KeyFrame& candidate,
                       const Sim3& S_keyframe_candidate,
                       std::vector<std::shared_ptr<MapPoint>>& matched, double radius,
                       const LoopMatchingOptions& options) {
  const auto own_points = keyframe.map_points();
  const auto candidate_points = candidate.map_points();
  std::unordered_set<const MapPoint*> already;
  for (const auto& point : matched) {
    if (point) already.insert(point.get());
  }
  // Each side's points are expressed in its own camera, then moved with the loop transform:
  // S_keyframe_world' = S_keyframe_candidate · T_candidate_world places candidate points in
  // `keyframe`; its inverse places the keyframe's points in the candidate. As poses rescaled to
  // each side's world units they project and measure distances exactly as the similarities do.
  const Pose candidate_in_keyframe =
      (S_keyframe_candidate * candidate.T_camera_world()).rescaled_pose();
  const Pose keyframe_in_candidate =
      (S_keyframe_candidate.inverse() * keyframe.T_camera_world()).rescaled_pose();
  const Eigen::Vector3d keyframe_center_in_candidate_world =
      candidate_in_keyframe.inverse().translation();
  const Eigen::Vector3d candidate_center_in_keyframe_world =
      keyframe_in_candidate.inverse().translation();

  std::vector<int> area;
  // Candidate point j -> keypoint of `keyframe`.
  std::vector<int> forward(candidate_points.size(), -1);
  for (size_t j = 0; j < candidate_points.size(); ++j) {
    const auto& point = candidate_points[j];
    if (!point || already.contains(point.get())) continue;
    Prediction prediction;
    if (!predict(keyframe, candidate_in_keyframe, keyframe_center_in_candidate_world, *point,
                 point->position(), prediction)) {
      continue;
    }
    forward[j] = best_in_area(keyframe, prediction, radius, point->descriptor(),
                              options.max_distance_loose, matched, area);
  }
  // Keypoint i of `keyframe` (its map point) -> keypoint of the candidate.
  int added = 0;
  for (int i = 0; i < keyframe.size(); ++i) {
    const auto& point = own_points[i];
    if (!point || matched[i]) continue;
    Prediction prediction;
    if (!predict(candidate, keyframe_in_candidate, candidate_center_in_keyframe_world, *point,
                 point->position(), prediction)) {
      continue;
    }
    const ScalePyramid& pyramid = candidate.pyramid();
    candidate.features_in_area(prediction.u, prediction.v, radius * pyramid.scale[prediction.level],
                               prediction.level - 1, prediction.level + 1, area);
    const OrbDescriptor descriptor = point->descriptor();
    int best_distance = INT_MAX;
    int best_j = -1;
    for (const int j : area) {
      const int d = descriptor_distance(descriptor, candidate.descriptor(j));
      if (d < best_distance) {
        best_distance = d;
        best_j = j;
      }
    }
    if (best_j < 0 || best_distance > options.max_distance_loose) continue;
    // Mutual: the candidate keypoint's own point must have chosen keypoint i.
    if (forward[best_j] != i || !candidate_points[best_j]) continue;
    matched[i] = candidate_points[best_j];
    ++added;
  }
  return added;
}

int match_by_projection(const KeyFrame& keyframe, const Pose& T_camera_world,
                        const std::vector<std::shared_ptr<MapPoint>>& points,
                        std::vector<std::shared_ptr<MapPoint>>& matched, double radius,
                        const LoopMatchingOptions& options) {
  std::unordered_set<const MapPoint*> already;
  for (const auto& point : matched) {
    if (point) already.insert(point.get());
  }
  const Eigen::Vector3d center = T_camera_world.inverse().translation();
  std::vector<int> area;
  int added = 0;
  for (const auto& point : points) {
    if (!point || point->is_bad() || already.contains(point.get())) continue;
    Prediction prediction;
    if (!predict(keyframe, T_camera_world, center, *point, point->position(), prediction)) {
      continue;
    }
    const int index = best_in_area(keyframe, prediction, radius, point->descriptor(),
                                   options.max_distance_strict, matched, area);
    if (index < 0) continue;
    matched[index] = point;
    already.insert(point.get());
    ++added;
  }
  return added;
}

}  // namespace pspslam
