#include "pspslam/loop/map_merge.h"

#include <unordered_set>
#include <vector>

#include "pspslam/loop/loop_detector.h"
#include "pspslam/map/keyframe.h"
#include "pspslam/map/map.h"
#include "pspslam/map/map_point.h"

namespace pspslam {

DetectedLoop bring_into_matched_map(Map& map, const DetectedLoop& loop) {
  const std::uint32_t from = loop.current->map_id();
  const std::uint32_t into = loop.matched->map_id();
  // The current camera seen from both worlds: S_current_world (matched side, in the current
  // map's units) and T_camera_world (current side), so x_into = S_current_world⁻¹ T x_from.
  const Sim3 S_into_from = loop.S_current_world.inverse() * Sim3(loop.current->T_camera_world());
  const Sim3 S_from_into = S_into_from.inverse();
  std::vector<std::shared_ptr<KeyFrame>> moving;
  for (const auto& keyframe : map.keyframes()) {
    if (!keyframe->is_bad() && keyframe->map_id() == from) moving.push_back(keyframe);
  }
  // Maps share no points, so every point a moving keyframe sees moves, once.
  std::unordered_set<std::uint64_t> moved_points;
  for (const auto& keyframe : moving) {
    for (const auto& point : keyframe->map_points()) {
      if (!point || point->is_bad() || !moved_points.insert(point->id()).second) continue;
      point->set_position(S_into_from * point->position());
    }
  }
  // S_k_into = T_k_from · S_from_into; a monocular map is rescaled into the matched map's units,
  // which keeps every projection as it was (Sim3::rescaled_pose).
  for (const auto& keyframe : moving) {
    keyframe->set_pose((Sim3(keyframe->T_camera_world()) * S_from_into).rescaled_pose());
  }
  for (const auto& keyframe : moving) {
    for (const auto& point : keyframe->map_points()) {
      if (point && !point->is_bad()) point->update_normal_and_depth(keyframe->pyramid());
    }
  }
  map.merge_map({.from = from,
                 .into = into,
                 .current_keyframe = loop.current->id(),
                 .matched_keyframe = loop.matched->id()});
  DetectedLoop merged = loop;
  merged.S_current_world = Sim3(loop.current->T_camera_world());
  merged.S_current_matched = merged.S_current_world * loop.matched->T_world_camera();
  return merged;
}

}  // namespace pspslam
