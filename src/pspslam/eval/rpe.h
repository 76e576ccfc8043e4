#pragma once

#include <limits>
#include <string>
#include <vector>

#include "pspslam/core/types.h"
#include "pspslam/eval/stats.h"

namespace pspslam {

// Unit of RpeOptions::delta, as evaluate_rpe.py's --delta_unit ('s' or 'f').
enum class RpeDeltaUnit { seconds, frames };

struct RpeOptions {
  double delta = 1.0;  // evaluate_rpe.py --delta with --fixed_delta
  RpeDeltaUnit unit = RpeDeltaUnit::seconds;
  double offset = 0.0;  // added to the estimate's timestamps (s)
};

struct RpePair {
  Timestamp est_from = 0.0, est_to = 0.0;
  Timestamp gt_from = 0.0, gt_to = 0.0;
  double translation_error = 0.0;  // m
  double rotation_error = 0.0;     // degrees
};

struct RpeResult {
  ErrorStats translation;  // m over one delta
  ErrorStats rotation;     // degrees over one delta
  // Each pair's error divided by the estimate's time between its two poses: drift rates that
  // compare across deltas and frame rates. Pairs with no time between them are left out.
  ErrorStats translation_per_second;  // m/s
  ErrorStats rotation_per_second;     // deg/s
  std::vector<RpePair> pairs;
  // Rotation between the body frames the two trajectories describe, estimated from the rotation
  // axes of the pairs' relative motions (a relative rotation of body B = A X is X^-1 R_A X: its
  // axis is the estimate's axis turned by X^-1). Near 0 when both trajectories are of the camera.
  // Far from 0 when the ground truth tracks another body, e.g. bonn_crowd_dev's motion-capture
  // marker set (171 degrees): the per-pair errors then compare motions in different frames, so
  // RPE means nothing while the ATE (positions only) stays valid. NaN when the turning pairs do
  // not determine it (fewer than 10 turn by >= 1 degree, or all about one axis).
  double body_frame_rotation_deg = std::numeric_limits<double>::quiet_NaN();
  static constexpr double kBodyFramesDifferDeg = 10.0;
  bool body_frames_differ() const { return body_frame_rotation_deg > kBodyFramesDifferDeg; }
};

// Relative pose error as TUM's evaluate_rpe.py with --fixed_delta (its result, pair for pair):
// for every estimated pose i, j is the pose closest to index_i + delta (time or frame index),
// the last pose excluded as j (as the script does); both ends are matched to the closest
// ground-truth stamps, pairs farther than twice the median ground-truth interval are dropped, and
// the error is E = (est_i^-1 est_j)^-1 (gt_i^-1 gt_j) -> |translation(E)|, angle(E).
// Unlike the script, pairs are never randomly subsampled (it samples 10000 of longer lists).
// Errors: fewer than 2 matching pairs.
RpeResult compute_rpe(const Trajectory& ground_truth, const Trajectory& estimate,
                      const RpeOptions& options = {});

std::string to_string(RpeDeltaUnit unit);  // "s" / "f"

}  // namespace pspslam
