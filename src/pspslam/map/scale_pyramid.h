#pragma once

#include <vector>

#include "pspslam/feature/orb_config.h"

namespace pspslam {

// Scale information of the ORB image pyramid (level l is the image scaled by 1/scale_factor^l).
// Matching windows, scale prediction and the observation information 1/sigma^2 all derive
// from it, so frames, keyframes and map points share one value instead of re-deriving it.
struct ScalePyramid {
  int levels = 1;
  double scale_factor = 1.2;
  double log_scale_factor = 0.0;
  std::vector<double> scale;       // scale_factor^level
  std::vector<double> inv_scale;   // 1 / scale
  std::vector<double> sigma2;      // scale^2: keypoint position variance per level
  std::vector<double> inv_sigma2;  // information of one observation at this level

  static ScalePyramid from_config(const OrbConfig& orb);

  // The level at which a point at `distance` would be observed, given that it is seen at
  // `max_distance` on level 0 (ORB-SLAM2's scale prediction), clamped to the pyramid.
  int predict_level(double distance, double max_distance) const;
};

}  // namespace pspslam
