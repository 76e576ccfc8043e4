// Tracking's relative-pose factor in bundle adjustment: its Jacobians, the pose information it is
// weighted by, and what it does to a BA solution.

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <random>

#include "optimize/synthetic_views.h"
#include "pspslam/optimize/local_bundle_adjustment.h"
#include "pspslam/optimize/pose_manifold.h"
#include "pspslam/optimize/pose_optimizer.h"
#include "pspslam/optimize/relative_pose_error.h"
#include "pspslam/optimize/rolling_shutter_pose.h"

namespace pspslam {
namespace {

using testing::make_pose;
using testing::test_bf;
using testing::test_camera;

using Matrix6 = Eigen::Matrix<double, 6, 6>;
using Vector6 = Eigen::Matrix<double, 6, 1>;

double smallest_eigenvalue(const Matrix6& symmetric) {
  return Eigen::SelfAdjointEigenSolver<Matrix6>(symmetric).eigenvalues().minCoeff();
}

Vector6 residual_at(const RelativePoseCost& cost, const PoseParameters& a,
                    const PoseParameters& b) {
  const double* parameters[] = {a.data(), b.data()};
  Vector6 r;
  cost.Evaluate(parameters, r.data(), nullptr);
  return r;
}

// The analytic tangent Jacobians against central differences through PoseManifold::Plus.
TEST(RelativePoseCost, JacobiansMatchFiniteDifferencesOfTheManifoldUpdate) {
  const Pose T_a = make_pose({0.1, -0.2, 0.05}, {0.3, 0.1, -0.2});
  const Pose T_b = make_pose({0.15, -0.1, 0.02}, {0.1, 0.25, -0.1});
  // A measurement off the current relative pose, so that the error is not the identity.
  const Pose measured = make_pose({0.02, 0.01, -0.03}, {0.01, -0.02, 0.015}) * T_b * T_a.inverse();
  Matrix6 information = Matrix6::Identity();
  information(0, 3) = information(3, 0) = 0.3;
  information.diagonal() << 4.0, 3.0, 2.0, 5.0, 1.0, 2.5;
  const RelativePoseCost cost(measured, information);

  const PoseParameters a = PoseParameters::from_pose(T_a);
  const PoseParameters b = PoseParameters::from_pose(T_b);
  Eigen::Matrix<double, 6, 7, Eigen::RowMajor> jacobian_a, jacobian_b;
  double* jacobians[] = {jacobian_a.data(), jacobian_b.data()};
  const double* parameters[] = {a.data(), b.data()};
  Vector6 residual;
  ASSERT_TRUE(cost.Evaluate(parameters, residual.data(), jacobians));
  EXPECT_GT(residual.norm(), 0.01);

  const PoseManifold manifold;
  constexpr double kStep = 1e-6;
  for (int which = 0; which < 2; ++which) {
    const PoseParameters& base = which == 0 ? a : b;
    const auto& analytic = which == 0 ? jacobian_a : jacobian_b;
    EXPECT_EQ(analytic.col(6).norm(), 0.0);
    for (int j = 0; j < 6; ++j) {
      Vector6 step = Vector6::Zero();
      step(j) = kStep;
      PoseParameters plus = base, minus = base;
      manifold.Plus(base.data(), step.data(), plus.data());
      step(j) = -kStep;
      manifold.Plus(base.data(), step.data(), minus.data());
      const Vector6 numeric =
          which == 0 ? (residual_at(cost, plus, b) - residual_at(cost, minus, b)) / (2 * kStep)
                     : (residual_at(cost, a, plus) - residual_at(cost, a, minus)) / (2 * kStep);
      EXPECT_LT((analytic.col(j) - numeric).norm(), 1e-6 * (1.0 + numeric.norm()))
          << "pose " << (which == 0 ? "a" : "b") << ", tangent column " << j;
    }
  }
}

TEST(RelativePoseCost, IsZeroAtTheMeasuredRelativePoseAndWeighsByTheInformation) {
  const Pose T_a = make_pose({0.1, 0.0, 0.0}, {0.0, 0.1, 0.0});
  const Pose T_b = make_pose({0.0, 0.2, 0.0}, {0.1, 0.0, 0.0});
  const PoseParameters a = PoseParameters::from_pose(T_a);
  const PoseParameters b = PoseParameters::from_pose(T_b);
  EXPECT_LT(
      residual_at(RelativePoseCost(T_b * T_a.inverse(), Matrix6::Identity()), a, b).squaredNorm(),
      1e-20);

  // 1 cm off along x in b's frame: χ² = 0.01² · information_xx.
  const Pose off = make_pose({0, 0, 0}, {0.01, 0.0, 0.0}) * T_b * T_a.inverse();
  Matrix6 information = Matrix6::Identity();
  information(3, 3) = 1e4;
  EXPECT_NEAR(residual_at(RelativePoseCost(off, information), a, b).squaredNorm(), 1.0, 1e-9);
}

// Observations of a pose: random points 1-5 m ahead with depth, 1 px noise.
struct PoseScene {
  Pose T_camera_world;
  std::vector<PoseObservation> observations;
};

PoseScene make_pose_scene(int points, bool with_depth, std::mt19937& rng) {
  const PinholeCamera camera = test_camera();
  PoseScene scene{make_pose({0.05, -0.1, 0.02}, {0.2, -0.1, 0.3}), {}};
  for (int i = 0; i < points; ++i) {
    const Eigen::Vector3d point =
        testing::random_visible_point(camera, scene.T_camera_world, 1.0, 5.0, rng);
    const auto measured = testing::measure(camera, test_bf(camera), scene.T_camera_world, point,
                                           with_depth, 1.0, 0, rng);
    scene.observations.push_back({point, measured.pixel, measured.right_u, measured.information});
  }
  return scene;
}

// The information is the inverse covariance of what optimize_pose returns under the noise it
// assumes: the spread of 300 noisy solutions matches it (Monte Carlo, within 25% per axis).
TEST(PoseInformation, PredictsTheSpreadOfThePoseOptimiser) {
  std::mt19937 rng(7);
  const PinholeCamera camera = test_camera();
  const double bf = test_bf(camera);
  PoseScene scene = make_pose_scene(60, /*with_depth=*/false, rng);
  const Matrix6 information =
      pose_information(camera, bf, {}, scene.T_camera_world, scene.observations);
  const Matrix6 predicted = information.inverse();

  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<Vector6> errors;
  for (int trial = 0; trial < 300; ++trial) {
    std::vector<PoseObservation> noisy = scene.observations;
    for (PoseObservation& o : noisy) {
      o.pixel = camera.project(scene.T_camera_world * o.point_world) +
                Eigen::Vector2d(noise(rng), noise(rng));
    }
    PoseOptimizerOptions options;
    options.robust_rounds = 0;
    options.chi2_mono = 1e9;  // every observation stays in: the plain least-squares estimate
    const Pose estimate =
        optimize_pose(camera, bf, scene.T_camera_world, noisy, options).T_camera_world;
    // The estimate as the left update of the truth: (Exp ω, v) · T_true.
    const Pose update = estimate * scene.T_camera_world.inverse();
    const Eigen::AngleAxisd angle_axis(update.rotation());
    Vector6 e;
    e << angle_axis.angle() * angle_axis.axis(), update.translation();
    errors.push_back(e);
  }
  Matrix6 sample = Matrix6::Zero();
  for (const Vector6& e : errors) sample += e * e.transpose();
  sample /= static_cast<double>(errors.size());
  for (int i = 0; i < 6; ++i) {
    EXPECT_NEAR(std::sqrt(sample(i, i) / predicted(i, i)), 1.0, 0.25) << "axis " << i;
  }
}

TEST(PoseInformation, GrowsWithDepthAndWithAPrior) {
  std::mt19937 rng(3);
  const PinholeCamera camera = test_camera();
  const double bf = test_bf(camera);
  const PoseScene flat = make_pose_scene(80, false, rng);
  std::vector<PoseObservation> with_depth = flat.observations;
  for (PoseObservation& o : with_depth) {
    const Eigen::Vector3d p = flat.T_camera_world * o.point_world;
    o.right_u = o.pixel.x() - bf / p.z();
  }
  const Matrix6 pixels_only =
      pose_information(camera, bf, {}, flat.T_camera_world, flat.observations);
  const Matrix6 depth = pose_information(camera, bf, {}, flat.T_camera_world, with_depth);
  // Depth adds a row per observation: the information only grows (PSD difference), along the
  // optical axis by half again even with ORB-SLAM2's weak u_r row.
  EXPECT_GT(smallest_eigenvalue(depth - pixels_only), -1e-6 * depth.norm());
  EXPECT_GT(depth(5, 5), 1.5 * pixels_only(5, 5));

  const PosePrior prior{flat.T_camera_world, 0.01, 0.002};
  const Matrix6 with_prior =
      pose_information(camera, bf, {}, flat.T_camera_world, flat.observations, &prior);
  EXPECT_NEAR(with_prior(0, 0) - pixels_only(0, 0), 1e4, 1e-6);
  EXPECT_NEAR(with_prior(3, 3) - pixels_only(3, 3), 2.5e5, 1e-4);
}

// Freeing the rotation rate can only lose information about the pose.
TEST(PoseInformation, RollingShutterMarginalIsBelowThePoseOnlyInformation) {
  std::mt19937 rng(11);
  const PinholeCamera camera = test_camera();
  const double bf = test_bf(camera);
  const PoseScene scene = make_pose_scene(150, true, rng);
  std::vector<double> row_times;
  for (const PoseObservation& o : scene.observations) {
    row_times.push_back(0.03 * (o.pixel.y() / camera.height - 0.5));
  }
  const RollingShutterPose refined = refine_pose_and_rotation_rate(
      camera, bf, {}, scene.T_camera_world, scene.observations, row_times, 0.5);
  const Matrix6 pose_only =
      pose_information(camera, bf, {}, refined.T_camera_world, scene.observations);
  ASSERT_GT(refined.pose_information.norm(), 0.0);
  const Matrix6 lost = pose_only - refined.pose_information;
  // Up to the refinement's last step (its H is taken one iterate before the returned pose).
  EXPECT_GT(smallest_eigenvalue(lost), -1e-4 * pose_only.norm());
  EXPECT_GT(lost.norm(), 1e-3 * pose_only.norm());  // the rate does take some of it
}

// Two keyframes; a is fixed, b sees 12 points with depth (a weak pose). A relative-pose factor that
// says b sits 2 cm further along x pulls b there in proportion to its weight.
TEST(BundleAdjustment, TrackingFactorPullsAWeakKeyframeTowardsItsMeasurement) {
  std::mt19937 rng(5);
  const PinholeCamera camera = test_camera();
  const double bf = test_bf(camera);
  const Pose T_a = make_pose({0, 0, 0}, {0, 0, 0});
  const Pose T_b = make_pose({0.0, 0.05, 0.0}, {-0.1, 0.0, 0.0});
  BaProblem truth;
  truth.keyframes = {{0, T_a, true}, {1, T_b, false}};
  for (int p = 0; p < 12; ++p) {
    const Eigen::Vector3d point = testing::random_visible_point(camera, T_b, 2.0, 4.0, rng);
    truth.points.push_back({static_cast<uint64_t>(p), point});
    for (size_t k = 0; k < 2; ++k) {
      const Pose& T = truth.keyframes[k].T_camera_world;
      const Eigen::Vector3d c = T * point;
      const Eigen::Vector2d pixel = camera.project(c);
      truth.observations.push_back({k, static_cast<size_t>(p), pixel, pixel.x() - bf / c.z(), 1.0});
    }
  }
  const Pose claimed = make_pose({0, 0, 0}, {0.02, 0.0, 0.0}) * T_b;
  const auto solve = [&](double information_scale) {
    BaProblem problem = truth;
    problem.relative_poses.push_back(
        {0, 1, claimed * T_a.inverse(), information_scale * Matrix6::Identity()});
    BaOptions options;
    options.huber_delta_relative_pose = 1e9;  // a quadratic factor: the pull is proportional
    solve_bundle_adjustment(problem, camera, bf, options);
    return (problem.keyframes[1].T_camera_world * T_b.inverse()).translation().x();
  };
  EXPECT_NEAR(solve(1e-6), 0.0, 1e-3);   // the observations win
  EXPECT_NEAR(solve(1e12), 0.02, 1e-3);  // the factor wins
  const double between = solve(1e5);
  EXPECT_GT(between, 0.002);
  EXPECT_LT(between, 0.018);
}

}  // namespace
}  // namespace pspslam
