#include "pspslam/tracking/mover_guard.h"

#include <Eigen/Geometry>

namespace pspslam {

bool MoverGuard::should_hold(const GuardedFrame& frame) {
  if (!watches(frame.on_stale_mask)) return false;
  const Pose difference = frame.optimised * frame.predicted.inverse();
  const double translation = difference.translation().norm();
  const double rotation = Eigen::AngleAxisd(difference.rotation()).angle();
  const bool jumped = translation > options_.translation_m || rotation > options_.rotation_rad;
  const bool fewer = mean_inliers_ > 0.0 && frame.inliers < options_.inlier_drop * mean_inliers_;
  const bool suspect = options_.enabled && jumped && fewer;
  if ((suspect || impossible_jump(frame, translation, rotation)) &&
      held_in_a_row_ < options_.max_hold_frames) {
    ++held_in_a_row_;
    return true;
  }
  held_in_a_row_ = 0;
  // Only believed frames feed the average, so that it remembers the healthy inlier count.
  mean_inliers_ = mean_inliers_ < 0.0 ? frame.inliers
                                      : options_.smoothing * frame.inliers +
                                            (1.0 - options_.smoothing) * mean_inliers_;
  return false;
}

bool MoverGuard::impossible_jump(const GuardedFrame& frame, double translation,
                                 double rotation) const {
  if (!frame.on_stale_mask || !options_.hold_jumps_on_stale_masks || frame.seconds <= 0.0)
    return false;
  return translation > options_.max_jump_speed_m_s * frame.seconds ||
         rotation > options_.max_jump_turn_rad_s * frame.seconds;
}

void MoverGuard::reset() {
  held_in_a_row_ = 0;
  mean_inliers_ = -1.0;
}

}  // namespace pspslam
