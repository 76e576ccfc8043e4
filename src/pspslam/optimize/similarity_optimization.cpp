#include "pspslam/optimize/similarity_optimization.h"

#include <ceres/ceres.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <limits>

namespace pspslam {

namespace {

// Parameters: quaternion (x, y, z, w; Eigen's order), translation, log of the scale.
struct TwoWayReprojectionError {
  TwoWayReprojectionError(const SimilarityPair& pair, const PinholeCamera& camera)
      : pair_(pair), camera_(camera) {}

  template <typename T>
  bool operator()(const T* quaternion, const T* translation, const T* log_scale,
                  T* residuals) const {
    const Eigen::Map<const Eigen::Quaternion<T>> rotation(quaternion);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t(translation);
    const T scale = ceres::exp(log_scale[0]);
    const Eigen::Matrix<T, 3, 1> b_in_a = scale * (rotation * pair_.in_b.cast<T>()) + t;
    const Eigen::Matrix<T, 3, 1> a_in_b =
        (rotation.conjugate() * (pair_.in_a.cast<T>() - t)) / scale;
    project(b_in_a, pair_.pixel_in_a, std::sqrt(pair_.information_a), residuals);
    project(a_in_b, pair_.pixel_in_b, std::sqrt(pair_.information_b), residuals + 2);
    return true;
  }

  template <typename T>
  void project(const Eigen::Matrix<T, 3, 1>& point, const Eigen::Vector2d& pixel, double weight,
               T* residual) const {
    residual[0] = weight * (camera_.fx * point.x() / point.z() + camera_.cx - pixel.x());
    residual[1] = weight * (camera_.fy * point.y() / point.z() + camera_.cy - pixel.y());
  }

  const SimilarityPair& pair_;
  const PinholeCamera& camera_;
};

double chi2_in(const PinholeCamera& camera, const Eigen::Vector3d& point,
               const Eigen::Vector2d& pixel, double information) {
  if (point.z() <= 0.0) return std::numeric_limits<double>::infinity();
  return (camera.project(point) - pixel).squaredNorm() * information;
}

}  // namespace

SimilarityOptimizationResult optimize_similarity(const PinholeCamera& camera, const Sim3& initial,
                                                 std::span<const SimilarityPair> pairs,
                                                 const SimilarityOptimizationOptions& options) {
  Eigen::Quaterniond quaternion(initial.rotation);
  quaternion.normalize();
  Eigen::Vector3d translation = initial.translation;
  double log_scale = std::log(initial.scale);
  std::vector<std::uint8_t> used(pairs.size(), 1);

  const auto solve = [&](int iterations) {
    ceres::Problem problem;
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      if (!used[k]) continue;
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<TwoWayReprojectionError, 4, 4, 3, 1>(
                                   new TwoWayReprojectionError(pairs[k], camera)),
                               new ceres::HuberLoss(std::sqrt(options.chi2)),
                               quaternion.coeffs().data(), translation.data(), &log_scale);
    }
    if (problem.NumResidualBlocks() == 0) return;
    problem.SetManifold(quaternion.coeffs().data(), new ceres::EigenQuaternionManifold);
    if (!options.estimate_scale) problem.SetParameterBlockConstant(&log_scale);
    ceres::Solver::Options solver;
    solver.max_num_iterations = iterations;
    solver.linear_solver_type = ceres::DENSE_QR;
    solver.num_threads = 1;
    ceres::Solver::Summary summary;
    ceres::Solve(solver, &problem, &summary);
  };
  const auto current = [&] {
    return Sim3(quaternion.normalized().toRotationMatrix(), translation, std::exp(log_scale));
  };
  // χ² test in both images with the given transform; flags[k] for each pair, returns the count.
  const auto mark_inliers = [&](const Sim3& S_a_b, std::vector<std::uint8_t>& flags) {
    const Sim3 S_b_a = S_a_b.inverse();
    int count = 0;
    flags.resize(pairs.size());
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      const SimilarityPair& pair = pairs[k];
      const bool in_a =
          chi2_in(camera, S_a_b * pair.in_b, pair.pixel_in_a, pair.information_a) <= options.chi2;
      const bool in_b =
          chi2_in(camera, S_b_a * pair.in_a, pair.pixel_in_b, pair.information_b) <= options.chi2;
      flags[k] = in_a && in_b ? 1 : 0;
      count += flags[k];
    }
    return count;
  };

  solve(options.first_iterations);
  mark_inliers(current(), used);
  solve(options.second_iterations);

  SimilarityOptimizationResult result;
  result.S_a_b = current();
  result.num_inliers = mark_inliers(result.S_a_b, result.inlier);
  return result;
}

}  // namespace pspslam
