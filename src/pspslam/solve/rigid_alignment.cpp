#include "pspslam/solve/rigid_alignment.h"

#include <Eigen/SVD>
#include <algorithm>
#include <array>
#include <cmath>
#include <random>

namespace pspslam {
namespace {

int count_inliers(std::span<const RigidCorrespondence> correspondences, const Sim3& T,
                  std::vector<std::uint8_t>* inlier) {
  int count = 0;
  for (size_t i = 0; i < correspondences.size(); ++i) {
    const RigidCorrespondence& c = correspondences[i];
    const bool ok = (c.target - T * c.source).squaredNorm() <= c.max_error * c.max_error;
    if (inlier != nullptr) (*inlier)[i] = ok ? 1 : 0;
    count += ok ? 1 : 0;
  }
  return count;
}

// Umeyama (1991): the rotation from the SVD of the weighted cross-covariance, then (optionally)
// the scale trace(D·sign) / Σ w |source − mean|², then the translation between the means.
std::optional<Sim3> align(std::span<const Eigen::Vector3d> source,
                          std::span<const Eigen::Vector3d> target, std::span<const double> weights,
                          bool with_scale) {
  const size_t n = source.size();
  if (n < 3 || target.size() != n || (!weights.empty() && weights.size() != n)) return std::nullopt;
  const auto weight = [&](size_t i) { return weights.empty() ? 1.0 : weights[i]; };
  double total = 0.0;
  Eigen::Vector3d source_mean = Eigen::Vector3d::Zero();
  Eigen::Vector3d target_mean = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    total += weight(i);
    source_mean += weight(i) * source[i];
    target_mean += weight(i) * target[i];
  }
  if (total <= 0.0) return std::nullopt;
  source_mean /= total;
  target_mean /= total;
  // Cross-covariance Σ w (t − t̄)(s − s̄)ᵀ; R = U diag(1, 1, det(UVᵀ)) Vᵀ maximises tr(Rᵀ Σ).
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  double source_spread = 0.0;
  for (size_t i = 0; i < n; ++i) {
    covariance += weight(i) * (target[i] - target_mean) * (source[i] - source_mean).transpose();
    source_spread += weight(i) * (source[i] - source_mean).squaredNorm();
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance,
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d singular = svd.singularValues();
  // Rank < 2 (all points on a line or one point): the rotation about that line is free.
  if (singular(1) <= 1e-12 * std::max(1.0, singular(0))) return std::nullopt;
  Eigen::Vector3d sign = Eigen::Vector3d::Ones();
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0) sign(2) = -1.0;
  Sim3 S;
  S.rotation = svd.matrixU() * sign.asDiagonal() * svd.matrixV().transpose();
  if (with_scale) {
    if (source_spread <= 0.0) return std::nullopt;
    S.scale = singular.dot(sign) / source_spread;
    if (!(S.scale > 0.0)) return std::nullopt;
  }
  S.translation = target_mean - S.scale * (S.rotation * source_mean);
  return S;
}

std::optional<Sim3> align_inliers(std::span<const RigidCorrespondence> correspondences,
                                  const std::vector<std::uint8_t>& inlier, bool with_scale) {
  std::vector<Eigen::Vector3d> source;
  std::vector<Eigen::Vector3d> target;
  for (size_t i = 0; i < correspondences.size(); ++i) {
    if (!inlier[i]) continue;
    source.push_back(correspondences[i].source);
    target.push_back(correspondences[i].target);
  }
  return align(source, target, {}, with_scale);
}

}  // namespace

std::optional<Pose> align_rigid(std::span<const Eigen::Vector3d> source,
                                std::span<const Eigen::Vector3d> target,
                                std::span<const double> weights) {
  const std::optional<Sim3> S = align(source, target, weights, /*with_scale=*/false);
  if (!S) return std::nullopt;
  Pose T = Pose::Identity();
  T.linear() = S->rotation;
  T.translation() = S->translation;
  return T;
}

std::optional<Sim3> align_similarity(std::span<const Eigen::Vector3d> source,
                                     std::span<const Eigen::Vector3d> target,
                                     std::span<const double> weights) {
  return align(source, target, weights, /*with_scale=*/true);
}

RigidRansacResult solve_rigid_ransac(std::span<const RigidCorrespondence> correspondences,
                                     const RigidRansacOptions& options) {
  RigidRansacResult result;
  const size_t n = correspondences.size();
  result.inlier.assign(n, 0);
  if (n < 3 || static_cast<int>(n) < options.min_inliers) return result;

  std::mt19937_64 random(options.seed);
  std::uniform_int_distribution<size_t> pick(0, n - 1);
  std::vector<std::uint8_t> candidate(n, 0);
  int best_inliers = 0;
  Sim3 best;
  int needed_iterations = options.max_iterations;
  std::array<Eigen::Vector3d, 3> source;
  std::array<Eigen::Vector3d, 3> target;
  for (int iteration = 0; iteration < std::min(options.max_iterations, needed_iterations);
       ++iteration) {
    ++result.iterations;
    size_t sample[3];
    sample[0] = pick(random);
    do sample[1] = pick(random);
    while (sample[1] == sample[0]);
    do sample[2] = pick(random);
    while (sample[2] == sample[0] || sample[2] == sample[1]);
    for (int k = 0; k < 3; ++k) {
      source[k] = correspondences[sample[k]].source;
      target[k] = correspondences[sample[k]].target;
    }
    const std::optional<Sim3> T = align(source, target, {}, options.estimate_scale);
    if (!T) continue;
    const int inliers = count_inliers(correspondences, *T, nullptr);
    if (inliers <= best_inliers) continue;
    best_inliers = inliers;
    best = *T;
    // Standard adaptive stop: enough samples that one was all-inlier with `confidence`.
    const double inlier_ratio = static_cast<double>(inliers) / static_cast<double>(n);
    const double all_inlier = std::pow(inlier_ratio, 3.0);
    if (all_inlier >= 1.0 - 1e-12) {
      needed_iterations = iteration + 1;
    } else if (all_inlier > 0.0) {
      needed_iterations = static_cast<int>(
          std::ceil(std::log(1.0 - options.confidence) / std::log(1.0 - all_inlier)));
    }
  }
  if (best_inliers < 3) return result;

  // Refit on the inliers; the larger inlier set of the refit usually grows once more.
  result.S_target_source = best;
  result.num_inliers = count_inliers(correspondences, best, &result.inlier);
  for (int refit = 0; refit < 2; ++refit) {
    const std::optional<Sim3> refined =
        align_inliers(correspondences, result.inlier, options.estimate_scale);
    if (!refined) break;
    const int inliers = count_inliers(correspondences, *refined, &candidate);
    if (inliers < result.num_inliers) break;
    result.S_target_source = *refined;
    result.num_inliers = inliers;
    result.inlier.swap(candidate);
  }
  result.success = result.num_inliers >= options.min_inliers;
  return result;
}

}  // namespace pspslam
