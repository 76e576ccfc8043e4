#pragma once

// New map points for a freshly inserted keyframe: from its own close depth readings and by
// triangulation against its covisible keyframes (ORB-SLAM2 CreateNewMapPoints, RGB-D variant).

#include <functional>
#include <memory>
#include <vector>

#include "pspslam/mapping/local_mapping_options.h"

namespace pspslam {

class KeyFrame;
class Map;
class MapPoint;

// Unprojects keypoints of `keyframe` that have depth but no map point, closest first: all
// closer than options.close_depth, and at least options.min_depth_points in total. Each new
// point is observed by `keyframe` only and added to `map`. Returns the new points.
std::vector<std::shared_ptr<MapPoint>> create_points_from_depth(
    Map& map, const std::shared_ptr<KeyFrame>& keyframe, const LocalMappingOptions& options);

// Triangulates matches between `keyframe` and its best covisible keyframes. A match becomes a
// point when it is in front of both cameras, reprojects within χ² (5.991 / 7.8) in both, and
// its distance ratio agrees with the keypoints' scale ratio. Where the rays' parallax is
// smaller than a depth reading's, the point is taken from that depth instead (RGB-D).
// should_stop is polled between neighbours (a new keyframe is waiting). Returns the new points.
std::vector<std::shared_ptr<MapPoint>> create_points_by_triangulation(
    Map& map, const std::shared_ptr<KeyFrame>& keyframe, const LocalMappingOptions& options,
    const std::function<bool()>& should_stop);

}  // namespace pspslam
