#pragma once

// Local bundle adjustment on the map (ORB-SLAM2 LocalBundleAdjustment): copies the local window
// into a plain BaProblem for optimize/, solves it without holding map locks, then writes the
// result back under Map::update_mutex() and erases the observations found to be outliers.

#include <memory>

#include "pspslam/optimize/local_bundle_adjustment.h"

namespace pspslam {

class KeyFrame;
class Map;

struct LocalBundleAdjustmentReport {
  int local_keyframes = 0;
  int fixed_keyframes = 0;
  int points = 0;
  int observations = 0;
  int outliers_removed = 0;
  double seconds = 0.0;
  BaResult result;
};

// Local keyframes: `keyframe` and its covisible keyframes, the best `max_covisibles` of them
// (0: all). Local points: all their map points. Fixed: the keyframes that observe local points
// without being local, and the anchor (id 0).
LocalBundleAdjustmentReport run_local_bundle_adjustment(Map& map,
                                                        const std::shared_ptr<KeyFrame>& keyframe,
                                                        const BaOptions& options,
                                                        size_t max_covisibles = 0);

}  // namespace pspslam
