#include "pspslam/mapping/keyframe_culling.h"

#include "pspslam/map/keyframe.h"
#include "pspslam/map/map.h"
#include "pspslam/map/map_point.h"

namespace pspslam {
namespace {

bool is_redundant(const KeyFrame& candidate, const LocalMappingOptions& options) {
  const std::vector<std::shared_ptr<MapPoint>> points = candidate.map_points();
  int considered = 0;
  int redundant = 0;
  for (int i = 0; i < static_cast<int>(points.size()); ++i) {
    const auto& point = points[i];
    if (!point) continue;
    // Only close points count: far ones are weakly constrained and say little about coverage.
    const float depth = candidate.depth(i);
    if (options.redundancy_needs_depth && (depth <= 0.0f || depth > options.close_depth)) continue;
    ++considered;
    if (point->num_observations() <= options.redundant_observers) continue;
    const int level = candidate.keypoints()[i].octave;
    int observers = 0;
    for (const auto& [keyframe_id, observation] : point->observations()) {
      if (keyframe_id == candidate.id()) continue;
      const auto other = observation.keyframe.lock();
      if (!other || other->is_bad()) continue;
      if (other->keypoints()[observation.keypoint_index].octave <= level + 1) ++observers;
      if (observers >= options.redundant_observers) break;
    }
    if (observers >= options.redundant_observers) ++redundant;
  }
  return considered > 0 && redundant > options.redundant_ratio * considered;
}

}  // namespace

int cull_redundant_keyframes(Map& map, const std::shared_ptr<KeyFrame>& keyframe,
                             const LocalMappingOptions& options,
                             const std::function<void(std::uint64_t)>& on_erased) {
  int culled = 0;
  for (const auto& candidate : keyframe->covisibles()) {
    if (candidate->is_anchor() || candidate->is_bad()) continue;
    if (!is_redundant(*candidate, options)) continue;
    const std::vector<std::shared_ptr<MapPoint>> points = candidate->map_points();
    map.erase_keyframe(candidate);
    if (!candidate->is_bad()) continue;
    ++culled;
    if (on_erased) on_erased(candidate->id());
    // Points left with too few observations turned bad; they must leave the map as well.
    for (const auto& point : points) {
      if (point && point->is_bad()) map.erase_map_point(point);
    }
  }
  return culled;
}

}  // namespace pspslam
