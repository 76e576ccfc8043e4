#include "pspslam/tracking/mover_guard.h"

#include <Eigen/Geometry>

namespace pspslam {

bool MoverGuard::should_hold(int inliers, const Pose& optimised, const Pose& predicted) {
  if (!options_.enabled) return false;
  const Pose difference = optimised * predicted.inverse();
  const double translation = difference.translation().norm();
  const double rotation = Eigen::AngleAxisd(difference.rotation()).angle();
  const bool jumped = translation > options_.translation_m || rotation > options_.rotation_rad;
  const bool fewer = mean_inliers_ > 0.0 && inliers < options_.inlier_drop * mean_inliers_;
  if (jumped && fewer && held_in_a_row_ < options_.max_hold_frames) {
    ++held_in_a_row_;
    return true;
  }
  held_in_a_row_ = 0;
  // Only believed frames feed the average, so that it remembers the healthy inlier count.
  mean_inliers_ = mean_inliers_ < 0.0
                      ? inliers
                      : options_.smoothing * inliers + (1.0 - options_.smoothing) * mean_inliers_;
  return false;
}

void MoverGuard::reset() {
  held_in_a_row_ = 0;
  mean_inliers_ = -1.0;
}

}  // namespace pspslam
