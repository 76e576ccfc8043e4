#pragma once

#include <memory>
#include <optional>

#include "pspslam/map/keyframe.h"

namespace pspslam {

class Frame;
class Map;

// Turns a tracked frame (it must have a pose) into a keyframe that is complete in the map's
// active map (Map::active_map):
// map points are created from depth for keypoints that have none, nearest first (all of them
// for the initial keyframe; otherwise every close one, at least `min_new_points`, as ORB-SLAM2's
// RGB-D keyframe creation), the frame's inlier matches become observations, descriptors,
// normals and covisibility are updated. The frame's associations are updated in place so the
// next frame tracks the new points.
// `motion`: what tracking measured since the previous keyframe (none for the first).
std::shared_ptr<KeyFrame> create_keyframe(Frame& frame, Map& map, bool initial,
                                          int min_new_points = 100,
                                          const std::optional<TrackedMotion>& motion = {});

}  // namespace pspslam
