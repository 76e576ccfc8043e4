#include "pspslam/optimize/global_bundle_adjustment.h"

#include <deque>
#include <memory>
#include <vector>

#include "pspslam/map/keyframe.h"
#include "pspslam/map/map.h"
#include "pspslam/map/map_point.h"
#include "pspslam/optimize/local_bundle_adjustment.h"

namespace pspslam {

GlobalBaResult solve_global_bundle_adjustment(const Map& map, const GlobalBaOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  GlobalBaResult result;
  BaProblem problem;
  std::unordered_map<std::uint64_t, size_t> keyframe_slot;
  std::shared_ptr<const KeyFrame> any_keyframe;
  for (const auto& keyframe : map.keyframes()) {
    if (keyframe->is_bad()) continue;
    if (options.map_id && keyframe->map_id() != *options.map_id) continue;
    const Pose T_camera_world = keyframe->T_camera_world();
    keyframe_slot.emplace(keyframe->id(), problem.keyframes.size());
    // Each map's first keyframe anchors it (gauge), as in local BA.
    problem.keyframes.push_back({keyframe->id(), T_camera_world, keyframe->is_anchor()});
    result.T_camera_world_before.emplace(keyframe->id(), T_camera_world);
    any_keyframe = keyframe;
  }
  for (const auto& point : map.map_points()) {
    if (point->is_bad()) continue;
    const size_t slot = problem.points.size();
    bool observed = false;
    for (const auto& [keyframe_id, observation] : point->observations()) {
      const auto it = keyframe_slot.find(keyframe_id);
      const auto observer = observation.keyframe.lock();
      if (it == keyframe_slot.end() || !observer || observer->is_bad()) continue;
      const int index = observation.keypoint_index;
      const cv::KeyPoint& keypoint = observer->keypoints()[index];
      problem.observations.push_back({it->second, slot,
                                      Eigen::Vector2d(keypoint.pt.x, keypoint.pt.y),
                                      static_cast<double>(observer->right_u(index)),
                                      observer->pyramid().inv_sigma2[keypoint.octave]});
      observed = true;
    }
    if (observed) problem.points.push_back({point->id(), point->position()});
  }
  result.keyframes = problem.keyframes.size();
  result.points = problem.points.size();
  result.observations = problem.observations.size();
  if (!any_keyframe || problem.observations.empty()) return result;

  BaOptions ba;
  ba.robust_iterations = options.iterations;
  ba.refine_iterations = 0;  // ORB-SLAM2's global BA keeps every observation (no second stage)
  ba.max_seconds = options.max_seconds;
  ba.depth_noise = options.depth_noise;
  ba.should_stop = options.should_stop;
  const CameraModel& camera = any_keyframe->camera();
  const BaResult solved = solve_bundle_adjustment(problem, camera.pinhole, camera.bf, ba);
  result.iterations = solved.iterations;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (options.should_stop && options.should_stop()) return result;
  for (const BaKeyframe& keyframe : problem.keyframes) {
    result.T_camera_world.emplace(keyframe.id, keyframe.T_camera_world);
  }
  for (const BaPoint& point : problem.points) {
    result.point_position.emplace(point.id, point.position_world);
  }
  result.completed = true;
  return result;
}

GlobalBaApplyReport apply_global_bundle_adjustment(Map& map, const GlobalBaResult& result) {
  GlobalBaApplyReport report;
  if (!result.completed) return report;
  // New poses for every keyframe: optimised ones as solved; newer ones through the spanning tree
  // from the root, keeping their pose relative to their parent (ORB-SLAM2's propagation).
  // before[id] is the pose the correction is measured against.
  std::unordered_map<std::uint64_t, Pose> corrected = result.T_camera_world;
  std::unordered_map<std::uint64_t, Pose> before = result.T_camera_world_before;
  const auto keyframes = map.keyframes();
  std::deque<std::shared_ptr<KeyFrame>> queue;
  for (const auto& keyframe : keyframes) {
    if (!keyframe->is_bad() && corrected.contains(keyframe->id()) && !keyframe->parent()) {
      queue.push_back(keyframe);  // roots of the spanning tree (normally keyframe 0 alone)
    }
  }
  std::unordered_map<std::uint64_t, bool> visited;
  while (!queue.empty()) {
    const auto keyframe = queue.front();
    queue.pop_front();
    if (visited[keyframe->id()]) continue;
    visited[keyframe->id()] = true;
    const Pose& parent_corrected = corrected.at(keyframe->id());
    const Pose& parent_before = before.at(keyframe->id());
    for (const auto& child : keyframe->children()) {
      if (child->is_bad()) continue;
      if (!corrected.contains(child->id())) {
        const Pose T_child_parent = child->T_camera_world() * parent_before.inverse();
        corrected[child->id()] = T_child_parent * parent_corrected;
        before[child->id()] = child->T_camera_world();
        ++report.keyframes_propagated;
      }
      queue.push_back(child);
    }
  }
  // Keyframes the tree walk did not reach (e.g. a new keyframe whose parent link is missing):
  // left as they are.
  std::unordered_map<std::uint64_t, Pose> applied_before;
  for (const auto& keyframe : keyframes) {
    const auto it = corrected.find(keyframe->id());
    if (keyframe->is_bad() || it == corrected.end()) continue;
    applied_before[keyframe->id()] = before.at(keyframe->id());
    keyframe->set_pose(it->second);
    if (result.T_camera_world.contains(keyframe->id())) ++report.keyframes_optimised;
  }

  for (const auto& point : map.map_points()) {
    if (point->is_bad()) continue;
    const auto solved = result.point_position.find(point->id());
    if (solved != result.point_position.end()) {
      point->set_position(solved->second);
      ++report.points_optimised;
    } else {
      // A point born during the solve: move it rigidly with its reference keyframe.
      const auto reference = point->reference_keyframe();
      if (!reference) continue;
      const auto it = applied_before.find(reference->id());
      if (it == applied_before.end()) continue;
      const Eigen::Vector3d in_camera = it->second * point->position();
      point->set_position(reference->T_world_camera() * in_camera);
      ++report.points_propagated;
    }
    if (const auto reference = point->reference_keyframe()) {
      point->update_normal_and_depth(reference->pyramid());
    }
  }
  return report;
}

}  // namespace pspslam
