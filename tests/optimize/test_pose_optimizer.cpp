#include "pspslam/optimize/pose_optimizer.h"

#include <gtest/gtest.h>

#include <random>

#include "optimize/synthetic_views.h"

namespace pspslam {
namespace {

using testing::measure;
using testing::perturb;
using testing::random_visible_point;
using testing::rotation_error_deg;
using testing::test_bf;
using testing::test_camera;
using testing::translation_error;

struct PoseScene {
  Pose true_T_camera_world;
  std::vector<PoseObservation> observations;
  std::vector<uint8_t> is_outlier;
};

// num_points correspondences, 1 px noise; a fraction of them replaced by a random pixel/depth.
PoseScene make_scene(int num_points, double outlier_fraction, double depth_fraction,
                     uint32_t seed) {
  std::mt19937 rng(seed);
  const PinholeCamera camera = test_camera();
  const double bf = test_bf(camera);
  PoseScene scene;
  scene.true_T_camera_world =
      testing::make_pose(Eigen::Vector3d(0.1, -0.3, 0.05), Eigen::Vector3d(0.4, -0.2, 1.5));
  std::bernoulli_distribution is_outlier(outlier_fraction);
  std::bernoulli_distribution has_depth(depth_fraction);
  std::uniform_real_distribution<double> u(0.0, camera.width);
  std::uniform_real_distribution<double> v(0.0, camera.height);
  for (int i = 0; i < num_points; ++i) {
    const Eigen::Vector3d point =
        random_visible_point(camera, scene.true_T_camera_world, 0.8, 6.0, rng);
    const bool with_depth = has_depth(rng);
    auto measurement =
        measure(camera, bf, scene.true_T_camera_world, point, with_depth, 1.0, 3, rng);
    const bool outlier = is_outlier(rng);
    if (outlier) {
      // A wrong match: somewhere else in the image, with an unrelated depth.
      measurement.pixel = {u(rng), v(rng)};
      if (with_depth) measurement.right_u = measurement.pixel.x() - bf / 2.0;
    }
    scene.observations.push_back(
        {point, measurement.pixel, measurement.right_u, measurement.information});
    scene.is_outlier.push_back(outlier);
  }
  return scene;
}

struct Classification {
  int outliers = 0, outliers_flagged = 0, inliers = 0, inliers_kept = 0;
};

Classification classify(const PoseScene& scene, const PoseOptimizationResult& result) {
  Classification c;
  for (size_t i = 0; i < scene.observations.size(); ++i) {
    if (scene.is_outlier[i]) {
      ++c.outliers;
      c.outliers_flagged += result.inlier[i] == 0;
    } else {
      ++c.inliers;
      c.inliers_kept += result.inlier[i] == 1;
    }
  }
  return c;
}

void expect_recovers(double outlier_fraction, double depth_fraction, uint32_t seed) {
  const PoseScene scene = make_scene(500, outlier_fraction, depth_fraction, seed);
  std::mt19937 rng(seed + 1000);
  const Pose initial = perturb(scene.true_T_camera_world, 3.0, 0.10, rng);
  const PinholeCamera camera = test_camera();
  // measure() draws u_r with pixel-sized noise: the ORB-SLAM2 u_r model is the matching one.
  PoseOptimizerOptions options;
  options.depth_noise.enabled = false;
  const PoseOptimizationResult result =
      optimize_pose(camera, test_bf(camera), initial, scene.observations, options);

  EXPECT_LT(rotation_error_deg(result.T_camera_world, scene.true_T_camera_world), 0.2);
  EXPECT_LT(translation_error(result.T_camera_world, scene.true_T_camera_world), 0.01);
  ASSERT_EQ(result.inlier.size(), scene.observations.size());
  const Classification c = classify(scene, result);
  // Random wrong matches land far from the projection: essentially all must be flagged.
  EXPECT_GE(c.outliers_flagged, c.outliers * 0.97) << c.outliers_flagged << "/" << c.outliers;
  // The 95% χ² gate rejects ~5% of correct matches by design.
  EXPECT_GE(c.inliers_kept, c.inliers * 0.90) << c.inliers_kept << "/" << c.inliers;
  EXPECT_EQ(result.num_inliers,
            static_cast<int>(std::count(result.inlier.begin(), result.inlier.end(), 1)));
}

TEST(PoseOptimizer, RecoversPoseWithDepthAnd25PercentOutliers) { expect_recovers(0.25, 1.0, 1); }

TEST(PoseOptimizer, RecoversPoseMixedDepthAnd30PercentOutliers) { expect_recovers(0.30, 0.6, 2); }

TEST(PoseOptimizer, RecoversPoseFromMonocularObservationsOnly) { expect_recovers(0.20, 0.0, 3); }

TEST(PoseOptimizer, ExactDataConvergesToTruePose) {
  PoseScene scene = make_scene(100, 0.0, 0.5, 4);
  const PinholeCamera camera = test_camera();
  const double bf = test_bf(camera);
  for (PoseObservation& observation : scene.observations) {  // remove the noise
    const Eigen::Vector3d p = scene.true_T_camera_world * observation.point_world;
    observation.pixel = camera.project(p);
    if (!std::isnan(observation.right_u)) observation.right_u = observation.pixel.x() - bf / p.z();
  }
  std::mt19937 rng(5);
  const Pose initial = perturb(scene.true_T_camera_world, 5.0, 0.2, rng);
  const PoseOptimizationResult result = optimize_pose(camera, bf, initial, scene.observations);
  EXPECT_LT(rotation_error_deg(result.T_camera_world, scene.true_T_camera_world), 1e-6);
  EXPECT_LT(translation_error(result.T_camera_world, scene.true_T_camera_world), 1e-8);
  EXPECT_EQ(result.num_inliers, 100);
}

TEST(PoseOptimizer, NoObservationsReturnsInitialPose) {
  const PinholeCamera camera = test_camera();
  const Pose initial = testing::make_pose({0.1, 0.2, 0.3}, {1.0, 2.0, 3.0});
  const PoseOptimizationResult result = optimize_pose(camera, test_bf(camera), initial, {});
  EXPECT_TRUE(result.T_camera_world.isApprox(initial, 0.0));
  EXPECT_EQ(result.num_inliers, 0);
  EXPECT_TRUE(result.inlier.empty());
}

TEST(PoseOptimizer, PointsBehindTheCameraAreOutliersAndPoseIsKept) {
  const PinholeCamera camera = test_camera();
  const Pose initial = Pose::Identity();
  std::vector<PoseObservation> observations;
  for (int i = 0; i < 20; ++i) {
    observations.push_back({Eigen::Vector3d(0.1 * i, 0.0, -2.0), {320.0, 240.0}, -1.0, 1.0});
  }
  const PoseOptimizationResult result =
      optimize_pose(camera, test_bf(camera), initial, observations);
  EXPECT_TRUE(result.T_camera_world.isApprox(initial, 0.0));
  EXPECT_EQ(result.num_inliers, 0);
  EXPECT_EQ(result.inlier, std::vector<uint8_t>(20, 0));
}

TEST(PoseOptimizer, TooFewObservationsDoNotCrash) {
  const PoseScene scene = make_scene(2, 0.0, 0.0, 6);
  const PinholeCamera camera = test_camera();
  const PoseOptimizationResult result =
      optimize_pose(camera, test_bf(camera), scene.true_T_camera_world, scene.observations);
  EXPECT_EQ(result.inlier.size(), 2u);
  EXPECT_TRUE(result.T_camera_world.matrix().allFinite());
}

// The prior is weighed against the observations: a loose one leaves the data's answer, a tight one
// pins the pose to itself, and exact data with a prior at the true pose stay exact.
TEST(PoseOptimizer, PriorIsWeighedAgainstTheObservations) {
  const PoseScene scene = make_scene(200, 0.0, 1.0, 7);
  const PinholeCamera camera = test_camera();
  const double bf = test_bf(camera);
  PoseOptimizerOptions options;
  options.depth_noise.enabled = false;
  const PoseOptimizationResult free =
      optimize_pose(camera, bf, scene.true_T_camera_world, scene.observations, options);
  std::mt19937 rng(8);
  const Pose elsewhere = perturb(scene.true_T_camera_world, 2.0, 0.05, rng);

  const PosePrior loose{elsewhere, 10.0, 100.0};
  const PoseOptimizationResult with_loose =
      optimize_pose(camera, bf, scene.true_T_camera_world, scene.observations, options, &loose);
  EXPECT_LT(translation_error(with_loose.T_camera_world, free.T_camera_world), 1e-6);
  EXPECT_LT(rotation_error_deg(with_loose.T_camera_world, free.T_camera_world), 1e-5);

  const PosePrior tight{elsewhere, 1e-9, 1e-9};
  const PoseOptimizationResult with_tight =
      optimize_pose(camera, bf, scene.true_T_camera_world, scene.observations, options, &tight);
  EXPECT_LT(translation_error(with_tight.T_camera_world, elsewhere), 1e-6);
  EXPECT_LT(rotation_error_deg(with_tight.T_camera_world, elsewhere), 1e-5);
  // Far from where the observations put it, the pose makes them outliers.
  EXPECT_LT(with_tight.num_inliers, 20);

  // Between the two (σ 1 mm / 1 mrad against 200 points with 1 px noise): the pose lands between
  // the data's answer and the prior, pinned to neither.
  const PosePrior medium{elsewhere, 1e-3, 1e-3};
  const PoseOptimizationResult with_medium =
      optimize_pose(camera, bf, scene.true_T_camera_world, scene.observations, options, &medium);
  const double free_distance = translation_error(free.T_camera_world, elsewhere);
  const double medium_distance = translation_error(with_medium.T_camera_world, elsewhere);
  EXPECT_LT(medium_distance, free_distance - 1e-3);
  EXPECT_GT(medium_distance, 1e-3);
  EXPECT_GT(translation_error(with_medium.T_camera_world, free.T_camera_world), 1e-3);
}

// The prior constrains what the observations leave free: two points without depth do not fix
// the six pose parameters, the prior (here at the true pose) supplies the rest.
TEST(PoseOptimizer, PriorFixesWhatTheObservationsLeaveFree) {
  PoseScene scene = make_scene(2, 0.0, 0.0, 9);
  const PinholeCamera camera = test_camera();
  const double bf = test_bf(camera);
  for (PoseObservation& observation : scene.observations)
    observation.pixel = camera.project(scene.true_T_camera_world * observation.point_world);
  std::mt19937 rng(10);
  const Pose initial = perturb(scene.true_T_camera_world, 1.0, 0.02, rng);
  const PosePrior prior{scene.true_T_camera_world, 0.01, 0.01};
  const PoseOptimizationResult result =
      optimize_pose(camera, bf, initial, scene.observations, {}, &prior);
  EXPECT_LT(translation_error(result.T_camera_world, scene.true_T_camera_world), 1e-6);
  EXPECT_LT(rotation_error_deg(result.T_camera_world, scene.true_T_camera_world), 1e-5);
}

}  // namespace
}  // namespace pspslam
