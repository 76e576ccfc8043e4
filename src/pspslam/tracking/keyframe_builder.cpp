#include "pspslam/tracking/keyframe_builder.h"

#include <algorithm>
#include <utility>
#include <vector>

#include "pspslam/map/frame.h"
#include "pspslam/map/keyframe.h"
#include "pspslam/map/map.h"
#include "pspslam/map/map_point.h"

namespace pspslam {

std::shared_ptr<KeyFrame> create_keyframe(Frame& frame, Map& map, bool initial, int min_new_points,
                                          const std::optional<TrackedMotion>& motion) {
  // Drop outlier associations before copying them into the keyframe.
  for (int i = 0; i < frame.size(); ++i) {
    if (frame.outlier[i]) {
      frame.map_points[i] = nullptr;
      frame.outlier[i] = 0;
    }
  }
  auto keyframe = std::make_shared<KeyFrame>(map.next_keyframe_id(), frame);
  if (motion) keyframe->set_tracked_motion(*motion);
  keyframe->set_map(map.active_map(), /*anchor=*/false);  // the map's first becomes its anchor
  map.add_keyframe(keyframe);

  // Existing matches become observations of the new keyframe.
  for (int i = 0; i < frame.size(); ++i) {
    const std::shared_ptr<MapPoint>& point = frame.map_points[i];
    if (!point || point->is_bad()) continue;
    if (point->is_observed_by(keyframe->id())) continue;
    point->add_observation(keyframe, i);
    point->update_normal_and_depth(frame.pyramid());
    point->compute_distinctive_descriptor();
  }

  // New points from depth, nearest first: near points have the most accurate depth.
  std::vector<std::pair<float, int>> by_depth;
  by_depth.reserve(frame.size());
  for (int i = 0; i < frame.size(); ++i) {
    if (frame.depth(i) > 0.0f) by_depth.emplace_back(frame.depth(i), i);
  }
  std::sort(by_depth.begin(), by_depth.end());
  const double depth_threshold = frame.camera().depth_threshold;
  int created_or_tracked = 0;
  for (const auto& [depth, i] : by_depth) {
    const std::shared_ptr<MapPoint>& existing = frame.map_points[i];
    if (existing && existing->num_observations() > 0) {
      ++created_or_tracked;
    } else {
      auto point =
          std::make_shared<MapPoint>(map.next_map_point_id(), frame.unproject_world(i), keyframe);
      point->add_observation(keyframe, i);
      keyframe->add_map_point(i, point);
      point->compute_distinctive_descriptor();
      point->update_normal_and_depth(frame.pyramid());
      map.add_map_point(point);
      frame.map_points[i] = point;
      ++created_or_tracked;
    }
    if (!initial && depth > depth_threshold && created_or_tracked > min_new_points) break;
  }
  keyframe->update_connections();
  return keyframe;
}

}  // namespace pspslam
