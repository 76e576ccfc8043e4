#pragma once

#include <Eigen/Core>
#include <vector>

#include "pspslam/core/types.h"
#include "pspslam/eval/stats.h"
#include "pspslam/io/association.h"

namespace pspslam {

struct AteOptions {
  // evaluate_ate.py --max_difference: ground truth / estimate association window (s).
  double max_difference = kDefaultMaxTimeDifference;
  // evaluate_ate.py --offset: added to the estimate's timestamps (s).
  double offset = 0.0;
  // false: rigid SE(3) alignment as evaluate_ate.py (RGB-D: metric scale is observable).
  // true: Sim(3) alignment with the least-squares scale of Umeyama (monocular).
  bool sim3 = false;
};

// x_aligned = scale * rotation * x + translation.
struct Alignment {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  double scale = 1.0;

  Eigen::Vector3d apply(const Eigen::Vector3d& point) const {
    return scale * (rotation * point) + translation;
  }
  // The inverse map: a ground-truth position into the estimate's frame (the viewers draw the
  // ground truth there, so the map and the estimate keep their own coordinates).
  Eigen::Vector3d inverse_apply(const Eigen::Vector3d& point) const {
    return rotation.transpose() * (point - translation) / scale;
  }
};

// Closed-form least-squares alignment of `model` onto `data` (3xN, columns paired), exactly as
// evaluate_ate.py's align(): SVD of the cross-covariance, reflection fixed by det(U)det(V) < 0.
// With `with_scale`, the scale is Umeyama's sum(singular values * signs) / sum |model - mean|^2.
Alignment align_points(const Eigen::Matrix3Xd& model, const Eigen::Matrix3Xd& data,
                       bool with_scale = false);

struct AtePair {
  Timestamp gt_timestamp = 0.0;
  Timestamp est_timestamp = 0.0;
  // Positions of the pair in the trajectories given to compute_ate (plots look up orientations).
  size_t gt_index = 0;
  size_t est_index = 0;
  Eigen::Vector3d gt_position = Eigen::Vector3d::Zero();
  Eigen::Vector3d est_aligned = Eigen::Vector3d::Zero();  // estimate after alignment
  double error = 0.0;                                     // |est_aligned - gt_position|, m
};

struct AteResult {
  ErrorStats error;            // metres, over `pairs`
  Alignment alignment;         // estimate -> ground-truth frame
  std::vector<AtePair> pairs;  // sorted by ground-truth timestamp
  // Every estimated position after alignment and every ground-truth position, in time order
  // (plots show the whole trajectories, not only the associated pairs).
  std::vector<Eigen::Vector3d> est_aligned_all;
  std::vector<Eigen::Vector3d> gt_all;
};

// Absolute trajectory error as TUM's evaluate_ate.py: associate ground truth (first) and
// estimate (second) timestamps like associate.py, align the estimate's positions onto the ground
// truth's, and summarise the position differences. Errors: fewer than 3 associated pairs
// ("ATE: only N of the M estimated poses have a ground-truth pose within X s ...").
AteResult compute_ate(const Trajectory& ground_truth, const Trajectory& estimate,
                      const AteOptions& options = {});

}  // namespace pspslam
