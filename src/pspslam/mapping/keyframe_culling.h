#pragma once

#include <cstdint>
#include <functional>
#include <memory>

#include "pspslam/mapping/local_mapping_options.h"

namespace pspslam {

class KeyFrame;
class Map;

// ORB-SLAM2 KeyFrameCulling: erases from `map` each covisible keyframe of `keyframe` (never the
// anchor of its map) whose close map points are more than options.redundant_ratio redundant, i.e.
// observed by at least options.redundant_observers other keyframes at the same or a finer
// pyramid level (one level of slack). Returns the number of keyframes erased; `on_erased` (may
// be empty) is told each erased keyframe's id (e.g. to drop it from the KeyFrameDatabase).
int cull_redundant_keyframes(Map& map, const std::shared_ptr<KeyFrame>& keyframe,
                             const LocalMappingOptions& options,
                             const std::function<void(std::uint64_t)>& on_erased = {});

}  // namespace pspslam
