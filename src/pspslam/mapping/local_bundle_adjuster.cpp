#include "pspslam/mapping/local_bundle_adjuster.h"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <optional>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include "pspslam/core/thread_cpu_time.h"
#include "pspslam/map/keyframe.h"
#include "pspslam/map/map.h"
#include "pspslam/map/map_point.h"

namespace pspslam {
namespace {

// The window as BaProblem indices plus the map objects they stand for (same order).
struct LocalWindow {
  BaProblem problem;
  std::vector<std::shared_ptr<KeyFrame>> keyframes;
  std::vector<std::shared_ptr<MapPoint>> points;
  std::vector<int> keypoint_index;  // per observation
};

// Tracking's factor of every window keyframe whose previous keyframe is in the window too.
void add_tracked_motions(LocalWindow& window,
                         const std::unordered_map<std::uint64_t, size_t>& keyframe_slot,
                         double weight) {
  for (size_t k = 0; k < window.keyframes.size(); ++k) {
    const std::optional<TrackedMotion>& motion = window.keyframes[k]->tracked_motion();
    if (!motion) continue;
    const auto previous = keyframe_slot.find(motion->previous_keyframe_id);
    if (previous == keyframe_slot.end()) continue;
    window.problem.relative_poses.push_back(
        {previous->second, k, motion->T_camera_previous, weight * motion->information});
  }
}

// The border keyframes a capped window keeps: those that see the most of its points (none: no
// cap, every keyframe that sees one).
std::optional<std::unordered_set<std::uint64_t>> best_border_keyframes(
    const LocalWindow& window, const std::unordered_map<std::uint64_t, size_t>& local_slot,
    size_t max_fixed) {
  if (max_fixed == 0) return std::nullopt;
  std::unordered_map<std::uint64_t, int> shared_points;
  for (const auto& point : window.points) {
    for (const auto& [keyframe_id, observation] : point->observations()) {
      if (!local_slot.contains(keyframe_id)) ++shared_points[keyframe_id];
    }
  }
  std::vector<std::pair<int, std::uint64_t>> ranked;
  for (const auto& [id, count] : shared_points) ranked.emplace_back(-count, id);
  std::sort(ranked.begin(), ranked.end());  // most shared first; ties by id: deterministic
  std::unordered_set<std::uint64_t> kept;
  for (size_t i = 0; i < std::min(max_fixed, ranked.size()); ++i) kept.insert(ranked[i].second);
  return kept;
}

LocalWindow collect_window(const std::shared_ptr<KeyFrame>& keyframe,
                           const LocalWindowOptions& options) {
  const size_t max_covisibles = options.max_covisibles;
  LocalWindow window;
  std::unordered_map<std::uint64_t, size_t> keyframe_slot;
  const auto add_keyframe = [&](const std::shared_ptr<KeyFrame>& kf, bool fixed) {
    keyframe_slot.emplace(kf->id(), window.keyframes.size());
    window.keyframes.push_back(kf);
    // The map's anchor keyframe fixes the gauge (position, orientation and scale of the map).
    window.problem.keyframes.push_back({kf->id(), kf->T_camera_world(), fixed || kf->is_anchor()});
  };
  add_keyframe(keyframe, false);
  for (const auto& neighbour :
       keyframe->best_covisibles(max_covisibles == 0 ? SIZE_MAX : max_covisibles)) {
    if (!neighbour->is_bad()) add_keyframe(neighbour, false);
  }
  const size_t num_local = window.keyframes.size();

  std::unordered_map<std::uint64_t, size_t> point_slot;
  for (size_t k = 0; k < num_local; ++k) {
    for (const auto& point : window.keyframes[k]->map_points()) {
      if (!point || point_slot.contains(point->id())) continue;
      point_slot.emplace(point->id(), window.points.size());
      window.points.push_back(point);
      window.problem.points.push_back({point->id(), point->position()});
    }
  }

  const std::optional<std::unordered_set<std::uint64_t>> border =
      best_border_keyframes(window, keyframe_slot, options.max_fixed_keyframes);
  for (size_t p = 0; p < window.points.size(); ++p) {
    for (const auto& [keyframe_id, observation] : window.points[p]->observations()) {
      const auto observer = observation.keyframe.lock();
      if (!observer || observer->is_bad()) continue;
      auto slot = keyframe_slot.find(keyframe_id);
      if (slot == keyframe_slot.end()) {
        if (border && !border->contains(keyframe_id)) continue;
        add_keyframe(observer, /*fixed=*/true);  // border keyframe: constrains, never moves
        slot = keyframe_slot.find(keyframe_id);
      }
      const int index = observation.keypoint_index;
      const cv::KeyPoint& keypoint = observer->keypoints()[index];
      window.problem.observations.push_back({slot->second, p,
                                             Eigen::Vector2d(keypoint.pt.x, keypoint.pt.y),
                                             static_cast<double>(observer->right_u(index)),
                                             observer->pyramid().inv_sigma2[keypoint.octave]});
      window.keypoint_index.push_back(index);
    }
  }
  if (options.tracked_motion_weight > 0.0) {
    add_tracked_motions(window, keyframe_slot, options.tracked_motion_weight);
  }
  return window;
}

}  // namespace

LocalBundleAdjustmentReport run_local_bundle_adjustment(Map& map,
                                                        const std::shared_ptr<KeyFrame>& keyframe,
                                                        const BaOptions& options,
                                                        const LocalWindowOptions& window_options) {
  const auto start = std::chrono::steady_clock::now();
  const double cpu_start_ms = thread_cpu_ms();
  LocalBundleAdjustmentReport report;
  LocalWindow window = collect_window(keyframe, window_options);
  report.relative_poses = static_cast<int>(window.problem.relative_poses.size());
  for (const BaKeyframe& kf : window.problem.keyframes) {
    (kf.fixed ? report.fixed_keyframes : report.local_keyframes) += 1;
  }
  report.points = static_cast<int>(window.points.size());
  report.observations = static_cast<int>(window.problem.observations.size());
  if (window.problem.observations.empty()) return report;

  const CameraModel& camera = keyframe->camera();
  report.result = solve_bundle_adjustment(window.problem, camera.pinhole, camera.bf, options);

  std::lock_guard lock(map.update_mutex());
  for (size_t i = 0; i < window.problem.observations.size(); ++i) {
    if (report.result.observation_inlier[i]) continue;
    const BaObservation& observation = window.problem.observations[i];
    const auto& observer = window.keyframes[observation.keyframe];
    const auto& point = window.points[observation.point];
    if (point->keypoint_index_in(observer->id()) != window.keypoint_index[i]) continue;
    observer->erase_map_point(window.keypoint_index[i]);
    if (point->erase_observation(observer->id())) map.erase_map_point(point);
    ++report.outliers_removed;
  }
  for (size_t k = 0; k < window.keyframes.size(); ++k) {
    if (!window.problem.keyframes[k].fixed) {
      window.keyframes[k]->set_pose(window.problem.keyframes[k].T_camera_world);
    }
  }
  for (size_t p = 0; p < window.points.size(); ++p) {
    const auto& point = window.points[p];
    if (point->is_bad()) continue;
    point->set_position(window.problem.points[p].position_world);
    point->update_normal_and_depth(keyframe->pyramid());
  }
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  report.cpu_ms = thread_cpu_ms() - cpu_start_ms;
  return report;
}

}  // namespace pspslam
