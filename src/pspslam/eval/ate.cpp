#include "pspslam/eval/ate.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cstdio>
#include <numeric>

#include "pspslam/core/error.h"

namespace pspslam {
namespace {

std::vector<size_t> time_order(const Trajectory& trajectory) {
  std::vector<size_t> order(trajectory.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::sort(order.begin(), order.end(),
            [&](size_t l, size_t r) { return trajectory[l].timestamp < trajectory[r].timestamp; });
  return order;
}

}  // namespace

Alignment align_points(const Eigen::Matrix3Xd& model, const Eigen::Matrix3Xd& data,
                       bool with_scale) {
  const Eigen::Vector3d model_mean = model.rowwise().mean();
  const Eigen::Vector3d data_mean = data.rowwise().mean();
  const Eigen::Matrix3Xd model_centered = model.colwise() - model_mean;
  const Eigen::Matrix3Xd data_centered = data.colwise() - data_mean;
  // evaluate_ate: W = sum outer(model_c, data_c); U d Vh = svd(W^T); rot = U S Vh.
  const Eigen::Matrix3d W_transposed = data_centered * model_centered.transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(W_transposed,
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d& U = svd.matrixU();
  const Eigen::Matrix3d Vh = svd.matrixV().transpose();
  Eigen::Vector3d signs(1.0, 1.0, 1.0);
  if (U.determinant() * Vh.determinant() < 0) signs.z() = -1.0;
  Alignment alignment;
  alignment.rotation = U * signs.asDiagonal() * Vh;
  if (with_scale) {
    const double model_spread = model_centered.squaredNorm();
    if (model_spread > 0.0) alignment.scale = svd.singularValues().dot(signs) / model_spread;
  }
  alignment.translation = data_mean - alignment.scale * (alignment.rotation * model_mean);
  return alignment;
}

AteResult compute_ate(const Trajectory& ground_truth, const Trajectory& estimate,
                      const AteOptions& options) {
  std::vector<Timestamp> gt_times, est_times;
  gt_times.reserve(ground_truth.size());
  est_times.reserve(estimate.size());
  for (const StampedPose& p : ground_truth) gt_times.push_back(p.timestamp);
  for (const StampedPose& p : estimate) est_times.push_back(p.timestamp);
  const std::vector<TimestampMatch> matches =
      associate_timestamps(gt_times, est_times, options.max_difference, options.offset);
  // Three points fix a rigid alignment; fewer means the files do not belong together.
  if (matches.size() < 3) {
    char window[32];
    std::snprintf(window, sizeof(window), "%g", options.max_difference);
    throw Error("ATE: only " + std::to_string(matches.size()) + " of the " +
                std::to_string(estimate.size()) +
                " estimated poses have a ground-truth pose within " + window +
                " s (need at least 3); wrong files, or do the timestamps need --offset?");
  }
  Eigen::Matrix3Xd gt_xyz(3, matches.size());
  Eigen::Matrix3Xd est_xyz(3, matches.size());
  for (size_t k = 0; k < matches.size(); ++k) {
    gt_xyz.col(k) = ground_truth[matches[k].first].T_world_camera.translation();
    est_xyz.col(k) = estimate[matches[k].second].T_world_camera.translation();
  }
  AteResult result;
  result.alignment = align_points(est_xyz, gt_xyz, options.sim3);
  std::vector<double> errors(matches.size());
  result.pairs.resize(matches.size());
  for (size_t k = 0; k < matches.size(); ++k) {
    AtePair& pair = result.pairs[k];
    pair.gt_timestamp = gt_times[matches[k].first];
    pair.est_timestamp = est_times[matches[k].second];
    pair.gt_index = matches[k].first;
    pair.est_index = matches[k].second;
    pair.gt_position = gt_xyz.col(k);
    pair.est_aligned = result.alignment.apply(est_xyz.col(k));
    pair.error = (pair.est_aligned - pair.gt_position).norm();
    errors[k] = pair.error;
  }
  result.error = compute_error_stats(std::move(errors));
  for (const size_t i : time_order(estimate)) {
    result.est_aligned_all.push_back(
        result.alignment.apply(estimate[i].T_world_camera.translation()));
  }
  for (const size_t i : time_order(ground_truth)) {
    result.gt_all.push_back(ground_truth[i].T_world_camera.translation());
  }
  return result;
}

}  // namespace pspslam
