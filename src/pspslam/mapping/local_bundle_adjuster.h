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
  int relative_poses = 0;  // tracking's factors in the problem
  double seconds = 0.0;
  // CPU time of the calling thread (Ceres runs on it): the cost itself, whatever the load.
  double cpu_ms = 0.0;
  BaResult result;
};

struct LocalWindowOptions {
  // The best this many covisible keyframes of the new one are local (0: all of them).
  size_t max_covisibles = 0;
  // Of the keyframes outside the window that see its points (held fixed), only the ones that see
  // the most of them (0: all). Bounds the problem where a revisited room has many such keyframes.
  size_t max_fixed_keyframes = 0;
  // Tracking's relative poses between keyframes of the window (KeyFrame::tracked_motion) join the
  // problem with their information times this weight (0: left out, ORB-SLAM2's BA).
  double tracked_motion_weight = 0.0;
};

// Local keyframes: `keyframe` and its covisible keyframes (LocalWindowOptions). Local points: all
// their map points. Fixed: the keyframes that observe local points without being local, and the
// anchor of the map (KeyFrame::is_anchor).
LocalBundleAdjustmentReport run_local_bundle_adjustment(Map& map,
                                                        const std::shared_ptr<KeyFrame>& keyframe,
                                                        const BaOptions& options,
                                                        const LocalWindowOptions& window = {});

}  // namespace pspslam
