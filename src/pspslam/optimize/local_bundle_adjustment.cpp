#include "pspslam/optimize/local_bundle_adjustment.h"

#include <ceres/iteration_callback.h>
#include <ceres/loss_function.h>
#include <ceres/ordered_groups.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <string>

#include "pspslam/core/error.h"
#include "pspslam/optimize/pose_manifold.h"
#include "pspslam/optimize/relative_pose_error.h"
#include "pspslam/optimize/reprojection_error.h"

namespace pspslam {

namespace {

using Clock = std::chrono::steady_clock;

bool has_depth(const BaObservation& observation) { return !std::isnan(observation.right_u); }

void check_indices(const BaProblem& problem) {
  for (size_t i = 0; i < problem.observations.size(); ++i) {
    const BaObservation& observation = problem.observations[i];
    if (observation.keyframe >= problem.keyframes.size() ||
        observation.point >= problem.points.size()) {
      throw Error("solve_bundle_adjustment: observation " + std::to_string(i) +
                  " references keyframe " + std::to_string(observation.keyframe) + " of " +
                  std::to_string(problem.keyframes.size()) + " / point " +
                  std::to_string(observation.point) + " of " +
                  std::to_string(problem.points.size()));
    }
  }
  for (size_t i = 0; i < problem.relative_poses.size(); ++i) {
    const BaRelativePose& factor = problem.relative_poses[i];
    if (factor.from >= problem.keyframes.size() || factor.to >= problem.keyframes.size()) {
      throw Error("solve_bundle_adjustment: relative pose " + std::to_string(i) +
                  " joins keyframes " + std::to_string(factor.from) + " and " +
                  std::to_string(factor.to) + " of " + std::to_string(problem.keyframes.size()));
    }
  }
}

double observation_chi_squared(const StereoProjection& model, const BaObservation& observation,
                               const PoseParameters& pose, const Eigen::Vector3d& point_world) {
  const Eigen::Vector3d point_camera = transform_point(pose.data(), point_world);
  const double sqrt_information = std::sqrt(observation.information);
  if (has_depth(observation)) {
    const Measurement<3> measured(observation.pixel.x(), observation.pixel.y(),
                                  observation.right_u);
    return chi_squared<3>(model, measured, sqrt_information, point_camera);
  }
  return chi_squared<2>(model, observation.pixel, sqrt_information, point_camera);
}

// Asks the caller after every iteration whether to go on; stopping keeps the current iterate.
class StopCallback final : public ceres::IterationCallback {
 public:
  explicit StopCallback(const std::function<bool()>& should_stop) : should_stop_(should_stop) {}

  ceres::CallbackReturnType operator()(const ceres::IterationSummary& /*summary*/) override {
    if (should_stop_ && should_stop_()) {
      stopped_ = true;
      return ceres::SOLVER_TERMINATE_SUCCESSFULLY;
    }
    return ceres::SOLVER_CONTINUE;
  }

  bool stopped() const { return stopped_; }

 private:
  const std::function<bool()>& should_stop_;
  bool stopped_ = false;
};

// Everything one stage needs; the stages differ in the kernel and the observation subset.
class BaStage {
 public:
  BaStage(const BaProblem& problem, const StereoProjection& model, const BaOptions& options)
      : problem_(problem), model_(model), options_(options) {}

  // Optimises over the observations flagged in `use`. Returns the number of iterations run.
  int solve(std::vector<PoseParameters>& poses, std::vector<Eigen::Vector3d>& points,
            const std::vector<uint8_t>& use, bool robust, int max_iterations, double max_seconds,
            StopCallback& stop_callback) {
    ceres::Problem::Options problem_options;
    problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;       // manifold_ is ours
    problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;  // and the loss
    ceres::Problem ceres_problem(problem_options);

    const double huber_mono = robust ? options_.huber_delta_mono : 0.0;
    const double huber_stereo = robust ? options_.huber_delta_stereo : 0.0;
    std::vector<uint8_t> pose_added(poses.size(), 0);
    std::vector<uint8_t> point_added(points.size(), 0);
    for (size_t i = 0; i < problem_.observations.size(); ++i) {
      if (!use[i]) continue;
      const BaObservation& observation = problem_.observations[i];
      double* pose = poses[observation.keyframe].data();
      double* point = points[observation.point].data();
      const double sqrt_information = std::sqrt(observation.information);
      if (has_depth(observation)) {
        const Measurement<3> measured(observation.pixel.x(), observation.pixel.y(),
                                      observation.right_u);
        auto pixel_rows = std::make_unique<BundleReprojectionCost<3, ObservationRows::kPixel>>(
            model_, measured, sqrt_information, huber_stereo);
        auto right_rows =
            std::make_unique<BundleReprojectionCost<3, ObservationRows::kRightPadded>>(
                model_, measured, sqrt_information, huber_stereo);
        ceres_problem.AddResidualBlock(pixel_rows.release(), nullptr, pose, point);
        ceres_problem.AddResidualBlock(right_rows.release(), nullptr, pose, point);
      } else {
        auto cost = std::make_unique<BundleReprojectionCost<2, ObservationRows::kPixel>>(
            model_, observation.pixel, sqrt_information, huber_mono);
        ceres_problem.AddResidualBlock(cost.release(), nullptr, pose, point);
      }
      pose_added[observation.keyframe] = 1;
      point_added[observation.point] = 1;
    }

    add_relative_poses(ceres_problem, poses, pose_added);

    // Schur elimination: points first (group 0), then the cameras (group 1).
    auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
    int free_keyframes = 0;
    for (size_t k = 0; k < poses.size(); ++k) {
      if (!pose_added[k]) continue;
      ceres_problem.SetManifold(poses[k].data(), &manifold_);
      if (problem_.keyframes[k].fixed) {
        ceres_problem.SetParameterBlockConstant(poses[k].data());
      } else {
        ++free_keyframes;
      }
      ordering->AddElementToGroup(poses[k].data(), 1);
    }
    int num_points = 0;
    for (size_t p = 0; p < points.size(); ++p) {
      if (!point_added[p]) continue;
      ordering->AddElementToGroup(points[p].data(), 0);
      ++num_points;
    }
    if (num_points == 0) return 0;

    ceres::Solver::Options solver_options;
    solver_options.linear_solver_type =
        free_keyframes <= options_.max_free_keyframes_for_dense_schur ? ceres::DENSE_SCHUR
                                                                      : ceres::SPARSE_SCHUR;
    solver_options.linear_solver_ordering = ordering;
    solver_options.max_num_iterations = max_iterations;
    solver_options.max_solver_time_in_seconds = std::max(max_seconds, 0.0);
    solver_options.num_threads = options_.num_threads;
    solver_options.logging_type = ceres::SILENT;
    solver_options.minimizer_progress_to_stdout = false;
    solver_options.callbacks.push_back(&stop_callback);

    ceres::Solver::Summary summary;
    ceres::Solve(solver_options, &ceres_problem, &summary);
    return summary.num_successful_steps + summary.num_unsuccessful_steps;
  }

 private:
  // Tracking's factors between keyframes already in the problem (the others have no pose block).
  void add_relative_poses(ceres::Problem& ceres_problem, std::vector<PoseParameters>& poses,
                          const std::vector<uint8_t>& pose_added) {
    for (const BaRelativePose& factor : problem_.relative_poses) {
      if (!pose_added[factor.from] || !pose_added[factor.to]) continue;
      if (problem_.keyframes[factor.from].fixed && problem_.keyframes[factor.to].fixed) continue;
      auto cost = std::make_unique<RelativePoseCost>(factor.T_to_from, factor.information);
      ceres_problem.AddResidualBlock(cost.release(), &relative_pose_loss_,
                                     poses[factor.from].data(), poses[factor.to].data());
    }
  }

  const BaProblem& problem_;
  StereoProjection model_;
  const BaOptions& options_;
  PoseManifold manifold_;
  ceres::HuberLoss relative_pose_loss_{options_.huber_delta_relative_pose};
};

}  // namespace

BaResult solve_bundle_adjustment(BaProblem& problem, const PinholeCamera& camera, double bf,
                                 const BaOptions& options) {
  check_indices(problem);
  const auto start = Clock::now();
  const auto seconds_left = [&] {
    return options.max_seconds - std::chrono::duration<double>(Clock::now() - start).count();
  };

  BaResult result;
  const size_t num_observations = problem.observations.size();
  result.observation_inlier.assign(num_observations, 0);
  if (num_observations == 0) return result;

  const StereoProjection model = StereoProjection::from(camera, bf, options.depth_noise);
  std::vector<PoseParameters> poses;
  poses.reserve(problem.keyframes.size());
  for (const BaKeyframe& keyframe : problem.keyframes) {
    poses.push_back(PoseParameters::from_pose(keyframe.T_camera_world));
  }
  std::vector<Eigen::Vector3d> points;
  points.reserve(problem.points.size());
  for (const BaPoint& point : problem.points) points.push_back(point.position_world);
  const std::vector<PoseParameters> initial_poses = poses;
  const std::vector<Eigen::Vector3d> initial_points = points;

  const auto chi2_of = [&](size_t i, const std::vector<PoseParameters>& pose_values,
                           const std::vector<Eigen::Vector3d>& point_values) {
    const BaObservation& observation = problem.observations[i];
    return observation_chi_squared(model, observation, pose_values[observation.keyframe],
                                   point_values[observation.point]);
  };
  const auto classify = [&](std::vector<uint8_t>& inlier) {
    classify_by_chi2(
        problem.observations, options.chi2_mono, options.chi2_stereo,
        [&](size_t i) { return chi2_of(i, poses, points); }, inlier);
  };

  // Stage 1 starts from everything in front of its camera (the cost is undefined behind it).
  std::vector<uint8_t>& inlier = result.observation_inlier;
  for (size_t i = 0; i < num_observations; ++i) {
    inlier[i] = std::isfinite(chi2_of(i, poses, points));
  }

  BaStage stage(problem, model, options);
  StopCallback stop_callback(options.should_stop);
  result.iterations += stage.solve(poses, points, inlier, /*robust=*/true,
                                   options.robust_iterations, seconds_left(), stop_callback);
  classify(inlier);
  if (!stop_callback.stopped() && seconds_left() > 0.0) {
    result.iterations += stage.solve(poses, points, inlier, /*robust=*/false,
                                     options.refine_iterations, seconds_left(), stop_callback);
    classify(inlier);
  }
  result.stopped_early = stop_callback.stopped() || seconds_left() <= 0.0;

  for (size_t i = 0; i < num_observations; ++i) {
    const double initial_chi2 = chi2_of(i, initial_poses, initial_points);
    // An observation that started behind its camera has no finite initial cost to compare.
    if (!inlier[i] || !std::isfinite(initial_chi2)) continue;
    result.initial_cost += 0.5 * initial_chi2;
    result.final_cost += 0.5 * chi2_of(i, poses, points);
  }
  for (size_t k = 0; k < problem.keyframes.size(); ++k) {
    if (!problem.keyframes[k].fixed) problem.keyframes[k].T_camera_world = poses[k].to_pose();
  }
  for (size_t p = 0; p < problem.points.size(); ++p) {
    problem.points[p].position_world = points[p];
  }
  return result;
}

}  // namespace pspslam
