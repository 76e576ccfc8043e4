#pragma once

#include "pspslam/core/types.h"

namespace pspslam {

struct MoverGuardOptions {
  // The inlier-drop rule (`--mover-guard`): a frame is suspect when its inliers fall below this
  // share of their recent average while its pose leaves the constant-velocity prediction by more
  // than these amounts.
  bool enabled = false;
  double inlier_drop = 0.7;
  double translation_m = 0.02;
  double rotation_rad = 0.02;
  // The jump rule (`--jump-guard`), for frames on a stale live mask only: a pose that leaves the
  // prediction faster than a hand-held or robot camera can move (6 m/s is 0.2 m in a 30 Hz frame,
  // 6 rad/s is 11 degrees) has followed people the stale mask missed.
  bool hold_jumps_on_stale_masks = true;
  double max_jump_speed_m_s = 6.0;
  double max_jump_turn_rad_s = 6.0;
  int max_hold_frames = 3;  // then the measurement is believed again
  double smoothing = 0.2;   // weight of the newest frame in the inlier average
};

// What the guard knows of a frame tracked with the motion model.
struct GuardedFrame {
  int inliers = 0;
  Pose optimised;      // T_camera_world
  Pose predicted;      // the constant-velocity prediction, T_camera_world
  double seconds = 0;  // since the frame the prediction was made from
  bool on_stale_mask = false;
};

// Notices when tracking's pose follows a moving cluster instead of the static world, in two ways:
// the static points it had matched fall away (fewer inliers than usual) while the pose leaves the
// motion model's prediction, as when the optimisation follows a crowd that fills the view; or, on
// a stale live mask, the pose leaves the prediction faster than a camera moves, as when the few
// static matches left in a crowd are outvoted by people the mask missed. For a few frames the pose
// is then held at the constant-velocity prediction. Pure bookkeeping; the tracker measures.
class MoverGuard {
 public:
  explicit MoverGuard(MoverGuardOptions options = {}) : options_(options) {}

  // Whether a rule can hold a frame with or without a stale mask (else the tracker skips it).
  bool watches(bool on_stale_mask) const {
    return options_.enabled || (on_stale_mask && options_.hold_jumps_on_stale_masks);
  }
  // Returns true when the frame's pose should be held at the prediction.
  bool should_hold(const GuardedFrame& frame);
  // A frame tracked otherwise (or lost): the next one starts afresh.
  void reset();

 private:
  bool impossible_jump(const GuardedFrame& frame, double translation, double rotation) const;

  MoverGuardOptions options_;
  double mean_inliers_ = -1.0;  // < 0: no healthy frame seen yet
  int held_in_a_row_ = 0;
};

}  // namespace pspslam
