#pragma once

#include <memory>

#include "pspslam/mapping/local_mapping_options.h"

namespace pspslam {

class KeyFrame;
class Map;

// ORB-SLAM2 KeyFrameCulling: erases from `map` each covisible keyframe of `keyframe` (never the
// anchor, id 0) whose close map points are more than options.redundant_ratio redundant, i.e.
// observed by at least options.redundant_observers other keyframes at the same or a finer
// pyramid level (one level of slack). Returns the number of keyframes erased.
int cull_redundant_keyframes(Map& map, const std::shared_ptr<KeyFrame>& keyframe,
                             const LocalMappingOptions& options);

}  // namespace pspslam
