#pragma once

#include "pspslam/core/types.h"

namespace pspslam {

struct MoverGuardOptions {
  bool enabled = false;
  // A frame is suspect when its inliers fall below this share of their recent average while its
  // pose leaves the constant-velocity prediction by more than these amounts.
  double inlier_drop = 0.7;
  double translation_m = 0.02;
  double rotation_rad = 0.02;
  int max_hold_frames = 3;  // then the measurement is believed again
  double smoothing = 0.2;   // weight of the newest frame in the inlier average
};

// Notices when tracking's inliers slide onto a moving cluster: the static points it had matched
// fall away (fewer inliers than usual) and the pose jumps off the motion model's prediction, as
// it does when the optimisation follows a crowd that fills the view. For a few frames the pose
// is then held at the constant-velocity prediction instead of following the people. Pure
// bookkeeping; the tracker measures.
class MoverGuard {
 public:
  explicit MoverGuard(MoverGuardOptions options = {}) : options_(options) {}

  // A frame tracked with the motion model: its inliers, its optimised pose and the prediction
  // (T_camera_world). Returns true when the pose should be held at the prediction.
  bool should_hold(int inliers, const Pose& optimised, const Pose& predicted);
  // A frame tracked otherwise (or lost): the next one starts afresh.
  void reset();

 private:
  MoverGuardOptions options_;
  double mean_inliers_ = -1.0;  // < 0: no healthy frame seen yet
  int held_in_a_row_ = 0;
};

}  // namespace pspslam
