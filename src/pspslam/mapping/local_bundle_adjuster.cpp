#include "pspslam/mapping/local_bundle_adjuster.h"

#include <chrono>
#include <cstdint>
#include <mutex>
#include <unordered_map>

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

LocalWindow collect_window(const std::shared_ptr<KeyFrame>& keyframe, size_t max_covisibles) {
  LocalWindow window;
  std::unordered_map<std::uint64_t, size_t> keyframe_slot;
  const auto add_keyframe = [&](const std::shared_ptr<KeyFrame>& kf, bool fixed) {
    keyframe_slot.emplace(kf->id(), window.keyframes.size());
    window.keyframes.push_back(kf);
    // The anchor keyframe fixes the gauge (position, orientation and scale of the map).
    window.problem.keyframes.push_back({kf->id(), kf->T_camera_world(), fixed || kf->id() == 0});
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

  for (size_t p = 0; p < window.points.size(); ++p) {
    for (const auto& [keyframe_id, observation] : window.points[p]->observations()) {
      const auto observer = observation.keyframe.lock();
      if (!observer || observer->is_bad()) continue;
      auto slot = keyframe_slot.find(keyframe_id);
      if (slot == keyframe_slot.end()) {
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
  return window;
}

}  // namespace

LocalBundleAdjustmentReport run_local_bundle_adjustment(Map& map,
                                                        const std::shared_ptr<KeyFrame>& keyframe,
                                                        const BaOptions& options,
                                                        size_t max_covisibles) {
  const auto start = std::chrono::steady_clock::now();
  LocalBundleAdjustmentReport report;
  LocalWindow window = collect_window(keyframe, max_covisibles);
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
  return report;
}

}  // namespace pspslam
