#include "pspslam/optimize/pose_optimizer.h"

#include <ceres/problem.h>
#include <ceres/sized_cost_function.h>
#include <ceres/solver.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <memory>

#include "pspslam/optimize/reprojection_error.h"

namespace pspslam {

namespace {

bool has_depth(const PoseObservation& observation) { return !std::isnan(observation.right_u); }

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

// The pose update of one round: δ = [ω; v] applied on the left of the round's base pose,
// T(δ) = (Exp(ω), v) · T_base, i.e. p_c = Exp(ω) q + v with q = T_base p_w.
Pose apply_update(const std::array<double, 6>& delta, const Pose& base) {
  const Eigen::Vector3d omega(delta[0], delta[1], delta[2]);
  Pose update = Pose::Identity();
  const double angle = omega.norm();
  if (angle > 0.0) update.linear() = Eigen::AngleAxisd(angle, omega / angle).toRotationMatrix();
  update.translation() = Eigen::Vector3d(delta[3], delta[4], delta[5]);
  return update * base;
}

// Left Jacobian of SO(3): Exp(ω + dω) ≈ Exp(J_l(ω) dω) Exp(ω).
Eigen::Matrix3d so3_left_jacobian(const Eigen::Vector3d& omega) {
  const double angle = omega.norm();
  const Eigen::Matrix3d skew = skew_symmetric(omega);
  if (angle < 1e-8) return Eigen::Matrix3d::Identity() + 0.5 * skew;
  const double angle2 = angle * angle;
  return Eigen::Matrix3d::Identity() + (1.0 - std::cos(angle)) / angle2 * skew +
         (angle - std::sin(angle)) / (angle2 * angle) * skew * skew;
}

// One selected observation, prepared for the inner loop: the point already in the base camera
// frame, the measurement and its weight.
struct PreparedObservation {
  Eigen::Vector3d point_base;
  Eigen::Vector3d measured;  // u, v, u_r (u_r unused without depth)
  double sqrt_information;
  bool has_depth;
};

// All selected observations of the frame as a single residual block over the 6-vector δ.
// Why one block and no Manifold: with one block per observation, Ceres' per-block bookkeeping
// (evaluation preparation, validity checks, the ambient-to-tangent Jacobian product of a
// manifold, building the problem each round) cost more than the residuals themselves. Here the
// parameter block is Euclidean (δ, re-based every round) and the inner loop is ours.
// Because Ceres applies a loss function to a whole block, the Huber kernel is applied inside, per
// observation (huber_scaling).
class FrameReprojectionCost final : public ceres::CostFunction {
 public:
  FrameReprojectionCost(const StereoProjection& model, std::vector<PreparedObservation> prepared,
                        bool robust, const PoseOptimizerOptions& options)
      : model_(model),
        prepared_(std::move(prepared)),
        robust_(robust),
        huber_delta_mono_(options.huber_delta_mono),
        huber_delta_stereo_(options.huber_delta_stereo) {
    int num_residuals = 0;
    for (const PreparedObservation& observation : prepared_) {
      num_residuals += observation.has_depth ? 3 : 2;
    }
    set_num_residuals(num_residuals);
    mutable_parameter_block_sizes()->push_back(6);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Eigen::Map<const Eigen::Vector3d> omega(parameters[0]);
    const Eigen::Map<const Eigen::Vector3d> translation(parameters[0] + 3);
    const double angle = omega.norm();
    const Eigen::Matrix3d rotation =
        angle > 0.0 ? Eigen::AngleAxisd(angle, omega / angle).toRotationMatrix()
                    : Eigen::Matrix3d::Identity();
    double* jacobian = jacobians != nullptr ? jacobians[0] : nullptr;
    const Eigen::Matrix3d left_jacobian =
        jacobian != nullptr ? so3_left_jacobian(omega) : Eigen::Matrix3d::Identity();
    int row = 0;
    for (const PreparedObservation& observation : prepared_) {
      const Eigen::Vector3d point_camera = rotation * observation.point_base + translation;
      double* jacobian_rows = jacobian != nullptr ? jacobian + row * 6 : nullptr;
      const bool ok = observation.has_depth
                          ? evaluate_one<3>(observation, point_camera, left_jacobian,
                                            residuals + row, jacobian_rows)
                          : evaluate_one<2>(observation, point_camera, left_jacobian,
                                            residuals + row, jacobian_rows);
      if (!ok) return false;  // a point went behind the camera: Ceres rejects the step
      row += observation.has_depth ? 3 : 2;
    }
    return true;
  }

 private:
  template <int kResiduals>
  bool evaluate_one(const PreparedObservation& observation, const Eigen::Vector3d& point_camera,
                    const Eigen::Matrix3d& left_jacobian, double* residual_out,
                    double* jacobian_out) const {
    Eigen::Matrix<double, kResiduals, 1> residual;
    Eigen::Matrix<double, kResiduals, 3> d_residual_d_point;
    if (!whitened_residual<kResiduals>(model_, observation.measured.head<kResiduals>(),
                                       observation.sqrt_information, point_camera, residual,
                                       jacobian_out ? &d_residual_d_point : nullptr)) {
      return false;
    }
    const double delta = !robust_ ? 0.0 : kResiduals == 3 ? huber_delta_stereo_ : huber_delta_mono_;
    const RobustScaling scaling = huber_scaling(residual.squaredNorm(), delta);
    residual *= scaling.residual;
    Eigen::Map<Eigen::Matrix<double, kResiduals, 1>> output(residual_out);
    output = residual;
    if (jacobian_out != nullptr) {
      // ∂p_c/∂ω = −[p_c]× J_l(ω), ∂p_c/∂v = I.
      const Eigen::Matrix3d minus_skew = -skew_symmetric(point_camera);
      Eigen::Map<Eigen::Matrix<double, kResiduals, 6, Eigen::RowMajor>> jacobian(jacobian_out);
      d_residual_d_point *= scaling.jacobian;
      jacobian.template leftCols<3>() = d_residual_d_point * (minus_skew * left_jacobian);
      jacobian.template rightCols<3>() = d_residual_d_point;
    }
    return true;
  }

  StereoProjection model_;
  std::vector<PreparedObservation> prepared_;
  bool robust_;
  double huber_delta_mono_;
  double huber_delta_stereo_;
};

// The prior's residual r = S (δ − δ_prior), where δ_prior = (Log R_d, t_d) with
// (R_d, t_d) = T_prior · T_base⁻¹ is the update that reaches the prior pose exactly and
// S = diag(1/σ_r, 1/σ_r, 1/σ_r, 1/σ_t, 1/σ_t, 1/σ_t). Linear in δ, so ∂r/∂δ = S.
class PosePriorCost final : public ceres::SizedCostFunction<6, 6> {
 public:
  PosePriorCost(const PosePrior& prior, const Pose& base) {
    const Pose difference = prior.T_camera_world * base.inverse();
    const Eigen::AngleAxisd angle_axis(difference.rotation());
    target_.head<3>() = angle_axis.angle() * angle_axis.axis();
    target_.tail<3>() = difference.translation();
    scale_.head<3>().setConstant(1.0 / prior.sigma_rotation);
    scale_.tail<3>().setConstant(1.0 / prior.sigma_translation);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Eigen::Map<const Eigen::Matrix<double, 6, 1>> delta(parameters[0]);
    Eigen::Map<Eigen::Matrix<double, 6, 1>> residual(residuals);
    residual = scale_.cwiseProduct(delta - target_);
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, 6, 6, Eigen::RowMajor>> jacobian(jacobians[0]);
      jacobian = scale_.asDiagonal();
    }
    return true;
  }

 private:
  Eigen::Matrix<double, 6, 1> target_;
  Eigen::Matrix<double, 6, 1> scale_;
};

std::vector<PreparedObservation> prepare(const std::vector<PoseObservation>& observations,
                                         const std::vector<uint8_t>& selected, const Pose& base) {
  std::vector<PreparedObservation> prepared;
  prepared.reserve(observations.size());
  for (size_t i = 0; i < observations.size(); ++i) {
    if (!selected[i]) continue;
    const PoseObservation& observation = observations[i];
    prepared.push_back({base * observation.point_world,
                        {observation.pixel.x(), observation.pixel.y(), observation.right_u},
                        std::sqrt(observation.information),
                        has_depth(observation)});
  }
  return prepared;
}

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

void classify_observations(const PinholeCamera& camera, double bf, const Pose& T_camera_world,
                           const std::vector<PoseObservation>& observations,
                           const PoseOptimizerOptions& options, std::vector<uint8_t>& inlier) {
  const StereoProjection model = StereoProjection::from(camera, bf, options.depth_noise);
  inlier.assign(observations.size(), 0);
  classify_by_chi2(
      observations, options.chi2_mono, options.chi2_stereo,
      [&](size_t i) { return observation_chi_squared(model, observations[i], T_camera_world); },
      inlier);
}

PoseOptimizationResult optimize_pose(const PinholeCamera& camera, double bf,
                                     const Pose& initial_T_camera_world,
                                     const std::vector<PoseObservation>& observations,
                                     const PoseOptimizerOptions& options, const PosePrior* prior) {
  PoseOptimizationResult result;
  result.T_camera_world = initial_T_camera_world;
  result.inlier.assign(observations.size(), 0);
  if (observations.empty()) return result;

  const StereoProjection model = StereoProjection::from(camera, bf, options.depth_noise);
  const ceres::Solver::Options solver_options = round_solver_options(options);
  Pose pose = initial_T_camera_world;

  // Every observation starts as an inlier unless it already lies behind the camera.
  std::vector<uint8_t>& inlier = result.inlier;
  for (size_t i = 0; i < observations.size(); ++i) {
    inlier[i] = std::isfinite(observation_chi_squared(model, observations[i], pose));
  }

  for (int round = 0; round < options.rounds; ++round) {
    if (std::find(inlier.begin(), inlier.end(), uint8_t{1}) == inlier.end()) break;
    const bool robust = round < options.robust_rounds;
    std::array<double, 6> delta{};  // starts at the current pose, which is the round's base
    ceres::Problem problem;
    auto cost = std::make_unique<FrameReprojectionCost>(model, prepare(observations, inlier, pose),
                                                        robust, options);
    problem.AddResidualBlock(cost.release(), nullptr, delta.data());
    if (prior != nullptr) {
      problem.AddResidualBlock(new PosePriorCost(*prior, pose), nullptr, delta.data());
    }
    ceres::Solver::Summary summary;
    ceres::Solve(solver_options, &problem, &summary);
    pose = apply_update(delta, pose);

    // Re-classify all observations, including earlier outliers: a better pose can redeem them.
    const int num_inliers = classify_by_chi2(
        observations, options.chi2_mono, options.chi2_stereo,
        [&](size_t i) { return observation_chi_squared(model, observations[i], pose); }, inlier);
    if (num_inliers < options.min_inliers_to_continue) break;
  }

  result.T_camera_world = pose;
  result.num_inliers = static_cast<int>(std::count(inlier.begin(), inlier.end(), uint8_t{1}));
  return result;
}

PoseInformation prior_information(const PosePrior& prior) {
  PoseInformation information = PoseInformation::Zero();
  information.diagonal().head<3>().setConstant(1.0 / (prior.sigma_rotation * prior.sigma_rotation));
  information.diagonal().tail<3>().setConstant(1.0 /
                                               (prior.sigma_translation * prior.sigma_translation));
  return information;
}

PoseInformation pose_information(const PinholeCamera& camera, double bf,
                                 const DepthNoiseModel& depth_noise, const Pose& T_camera_world,
                                 const std::vector<PoseObservation>& observations,
                                 const PosePrior* prior) {
  PoseInformation information =
      prior != nullptr ? prior_information(*prior) : PoseInformation::Zero();
  // The observations in front of the camera (whitened_residual's own bound): one behind it would
  // make the cost refuse the whole evaluation.
  std::vector<uint8_t> in_front(observations.size(), 0);
  for (size_t i = 0; i < observations.size(); ++i) {
    in_front[i] = (T_camera_world * observations[i].point_world).z() >= 1e-6;
  }
  PoseOptimizerOptions options;
  options.depth_noise = depth_noise;
  const FrameReprojectionCost cost(StereoProjection::from(camera, bf, depth_noise),
                                   prepare(observations, in_front, T_camera_world),
                                   /*robust=*/false, options);
  if (cost.num_residuals() == 0) return information;
  // The Jacobian at δ = 0 of the optimiser's own residuals: JᵀJ is its Gauss-Newton information.
  const std::array<double, 6> delta{};
  const double* parameters[] = {delta.data()};
  std::vector<double> residuals(cost.num_residuals());
  Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor> jacobian(cost.num_residuals(), 6);
  double* jacobians[] = {jacobian.data()};
  if (cost.Evaluate(parameters, residuals.data(), jacobians)) {
    information.noalias() += jacobian.transpose() * jacobian;
  }
  return information;
}

}  // namespace pspslam
