#include "pspslam/optimize/pose_optimizer.h"

#include <ceres/problem.h>
#include <ceres/solver.h>

#include <algorithm>
#include <memory>

#include "pspslam/optimize/pose_manifold.h"
#include "pspslam/optimize/reprojection_error.h"

namespace pspslam {

namespace {

bool has_depth(const PoseObservation& observation) { return observation.right_u >= 0.0; }

double observation_chi_squared(const StereoProjection& model, const PoseObservation& observation,
                               const Pose& T_camera_world) {
  const Eigen::Vector3d point_camera = T_camera_world * observation.point_world;
  const double sqrt_information = std::sqrt(observation.information);
  if (has_depth(observation)) {
    const Measurement<3> measured(observation.pixel.x(), observation.pixel.y(),
                                  observation.right_u);
    return chi_squared<3>(model, measured, sqrt_information, point_camera);
  }
  return chi_squared<2>(model, observation.pixel, sqrt_information, point_camera);
}

// All selected observations of the frame as a single residual block over the pose. One block per
// observation made Ceres' per-block bookkeeping (evaluation preparation, validity checks, building
// the problem each round) dominate the run time; here the inner loop is ours and allocation-free.
// Because Ceres applies a loss function to a whole block, the Huber kernel is applied inside, per
// observation, the way g2o does it: the residual is scaled to carry ρ(s) (so the cost is the
// robust cost) and the Jacobian is weighted by √ρ'(s) (iteratively reweighted least squares).
class FrameReprojectionCost final : public ceres::CostFunction {
 public:
  FrameReprojectionCost(const StereoProjection& model,
                        const std::vector<PoseObservation>& observations,
                        const std::vector<uint8_t>& selected, bool robust,
                        const PoseOptimizerOptions& options)
      : model_(model),
        observations_(observations),
        robust_(robust),
        huber_delta_mono_(options.huber_delta_mono),
        huber_delta_stereo_(options.huber_delta_stereo) {
    int num_residuals = 0;
    for (size_t i = 0; i < observations.size(); ++i) {
      if (!selected[i]) continue;
      selected_.push_back(i);
      num_residuals += has_depth(observations[i]) ? 3 : 2;
    }
    set_num_residuals(num_residuals);
    mutable_parameter_block_sizes()->push_back(PoseParameters::kAmbientSize);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    double* jacobian = jacobians != nullptr ? jacobians[0] : nullptr;
    int row = 0;
    for (const size_t index : selected_) {
      const PoseObservation& observation = observations_[index];
      const bool ok = has_depth(observation)
                          ? evaluate_one<3>(observation, parameters[0], residuals + row,
                                            jacobian ? jacobian + row * 7 : nullptr)
                          : evaluate_one<2>(observation, parameters[0], residuals + row,
                                            jacobian ? jacobian + row * 7 : nullptr);
      if (!ok) return false;  // a point went behind the camera: Ceres rejects the step
      row += has_depth(observation) ? 3 : 2;
    }
    return true;
  }

 private:
  template <int kResiduals>
  bool evaluate_one(const PoseObservation& observation, const double* pose, double* residual_out,
                    double* jacobian_out) const {
    Measurement<kResiduals> measured;
    measured.template head<2>() = observation.pixel;
    if constexpr (kResiduals == 3) measured(2) = observation.right_u;
    const Eigen::Vector3d point_camera = transform_point(pose, observation.point_world);
    Eigen::Matrix<double, kResiduals, 1> residual;
    Eigen::Matrix<double, kResiduals, 3> d_residual_d_point;
    if (!whitened_residual<kResiduals>(model_, measured, std::sqrt(observation.information),
                                       point_camera, residual,
                                       jacobian_out ? &d_residual_d_point : nullptr)) {
      return false;
    }
    const double delta = kResiduals == 3 ? huber_delta_stereo_ : huber_delta_mono_;
    const double squared_norm = residual.squaredNorm();
    if (robust_ && squared_norm > delta * delta) {
      // Huber: ρ(s) = 2δ√s − δ², ρ'(s) = δ/√s for s > δ².
      const double norm = std::sqrt(squared_norm);
      residual *= std::sqrt((2.0 * delta * norm - delta * delta) / squared_norm);
      if (jacobian_out != nullptr) d_residual_d_point *= std::sqrt(delta / norm);
    }
    Eigen::Map<Eigen::Matrix<double, kResiduals, 1>> output(residual_out);
    output = residual;
    if (jacobian_out != nullptr) {
      write_pose_jacobian<kResiduals>(d_residual_d_point, point_camera, jacobian_out);
    }
    return true;
  }

  StereoProjection model_;
  const std::vector<PoseObservation>& observations_;
  std::vector<size_t> selected_;
  bool robust_;
  double huber_delta_mono_;
  double huber_delta_stereo_;
};

ceres::Solver::Options round_solver_options(const PoseOptimizerOptions& options) {
  ceres::Solver::Options solver_options;
  // Six unknowns: forming JᵀJ and a 6×6 Cholesky is the cheapest exact solve.
  solver_options.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  solver_options.max_num_iterations = options.iterations_per_round;
  solver_options.num_threads = 1;
  // Rotation (rad) and translation (m) columns are of similar magnitude for camera-scale scenes;
  // skipping the column scaling saves two passes over the Jacobian per iteration.
  solver_options.jacobi_scaling = false;
  solver_options.logging_type = ceres::SILENT;
  solver_options.minimizer_progress_to_stdout = false;
  return solver_options;
}

}  // namespace

PoseOptimizationResult optimize_pose(const PinholeCamera& camera, double bf,
                                     const Pose& initial_T_camera_world,
                                     const std::vector<PoseObservation>& observations,
                                     const PoseOptimizerOptions& options) {
  PoseOptimizationResult result;
  result.T_camera_world = initial_T_camera_world;
  result.inlier.assign(observations.size(), 0);
  if (observations.empty()) return result;

  const StereoProjection model = StereoProjection::from(camera, bf);
  PoseParameters pose = PoseParameters::from_pose(initial_T_camera_world);
  PoseManifold manifold;
  const ceres::Solver::Options solver_options = round_solver_options(options);
  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;  // lives on this frame

  // Every observation starts as an inlier unless it already lies behind the camera.
  std::vector<uint8_t>& inlier = result.inlier;
  for (size_t i = 0; i < observations.size(); ++i) {
    inlier[i] =
        std::isfinite(observation_chi_squared(model, observations[i], initial_T_camera_world));
  }

  for (int round = 0; round < options.rounds; ++round) {
    if (std::find(inlier.begin(), inlier.end(), uint8_t{1}) == inlier.end()) break;
    const bool robust = round < options.robust_rounds;
    ceres::Problem problem(problem_options);
    problem.AddParameterBlock(pose.data(), PoseParameters::kAmbientSize, &manifold);
    auto cost = std::make_unique<FrameReprojectionCost>(model, observations, inlier, robust,
                                                        options);
    problem.AddResidualBlock(cost.release(), nullptr, pose.data());

    ceres::Solver::Summary summary;
    ceres::Solve(solver_options, &problem, &summary);

    // Re-classify all observations, including earlier outliers: a better pose can redeem them.
    const Pose current = pose.to_pose();
    int num_inliers = 0;
    for (size_t i = 0; i < observations.size(); ++i) {
      const double threshold = has_depth(observations[i]) ? options.chi2_stereo : options.chi2_mono;
      inlier[i] = observation_chi_squared(model, observations[i], current) <= threshold;
      num_inliers += inlier[i];
    }
    if (num_inliers < options.min_inliers_to_continue) break;
  }

  result.T_camera_world = pose.to_pose();
  result.num_inliers = static_cast<int>(std::count(inlier.begin(), inlier.end(), uint8_t{1}));
  return result;
}

}  // namespace pspslam
