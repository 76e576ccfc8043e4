#include "pspslam/optimize/local_bundle_adjustment.h"

#include <gtest/gtest.h>

#include <random>

#include "optimize/synthetic_views.h"
#include "pspslam/core/error.h"

namespace pspslam {
namespace {

using testing::rotation_error_deg;
using testing::test_bf;
using testing::test_camera;
using testing::translation_error;

struct BaScene {
  BaProblem truth;    // exact poses and points
  BaProblem problem;  // perturbed start, noisy measurements
  std::vector<uint8_t> is_outlier;
};

// num_keyframes cameras on a line looking down +z, the first num_fixed held constant; points in
// a slab 2–6 m ahead; 1 px noise; a fraction of the observations replaced by random pixels.
BaScene make_scene(int num_keyframes, int num_fixed, int num_points, double depth_fraction,
                   double outlier_fraction, uint32_t seed) {
  std::mt19937 rng(seed);
  const PinholeCamera camera = test_camera();
  const double bf = test_bf(camera);
  BaScene scene;
  for (int k = 0; k < num_keyframes; ++k) {
    const Pose T_world_camera = testing::make_pose(Eigen::Vector3d(0.0, 0.02 * k, 0.0),
                                                   Eigen::Vector3d(0.15 * k, 0.0, 0.0));
    scene.truth.keyframes.push_back(
        {static_cast<uint64_t>(k), T_world_camera.inverse(), k < num_fixed});
  }
  std::uniform_real_distribution<double> x(-2.0, 3.0), y(-1.5, 1.5), z(2.0, 6.0);
  for (int p = 0; p < num_points; ++p) {
    scene.truth.points.push_back(
        {static_cast<uint64_t>(p), Eigen::Vector3d(x(rng), y(rng), z(rng))});
  }

  scene.problem = scene.truth;
  std::bernoulli_distribution has_depth(depth_fraction), is_outlier(outlier_fraction);
  std::uniform_real_distribution<double> u(0.0, camera.width), v(0.0, camera.height);
  for (size_t k = 0; k < scene.truth.keyframes.size(); ++k) {
    const Pose& T_camera_world = scene.truth.keyframes[k].T_camera_world;
    for (size_t p = 0; p < scene.truth.points.size(); ++p) {
      const Eigen::Vector3d point_camera = T_camera_world * scene.truth.points[p].position_world;
      if (point_camera.z() < 0.1 || !camera.in_image(camera.project(point_camera), 10.0)) continue;
      auto measurement =
          testing::measure(camera, bf, T_camera_world, scene.truth.points[p].position_world,
                           has_depth(rng), 1.0, 2, rng);
      const bool outlier = is_outlier(rng);
      if (outlier) measurement.pixel = {u(rng), v(rng)};
      scene.problem.observations.push_back(
          {k, p, measurement.pixel, measurement.right_u, measurement.information});
      scene.is_outlier.push_back(outlier);
    }
  }

  for (BaKeyframe& keyframe : scene.problem.keyframes) {
    if (!keyframe.fixed)
      keyframe.T_camera_world = testing::perturb(keyframe.T_camera_world, 1.0, 0.05, rng);
  }
  std::normal_distribution<double> point_noise(0.0, 0.03);
  for (BaPoint& point : scene.problem.points) {
    point.position_world += Eigen::Vector3d(point_noise(rng), point_noise(rng), point_noise(rng));
  }
  return scene;
}

// make_scene draws u_r with pixel-sized noise: the ORB-SLAM2 u_r model is the matching one.
BaOptions u_r_model_options() {
  BaOptions options;
  options.depth_noise.enabled = false;
  return options;
}

// RMS over (u, v) of the whitened residual of the inlier observations: ≈ 1 at the noise level.
double rms_whitened_reprojection(const BaProblem& problem, const std::vector<uint8_t>& inlier) {
  const PinholeCamera camera = test_camera();
  double sum = 0.0;
  int count = 0;
  for (size_t i = 0; i < problem.observations.size(); ++i) {
    if (!inlier[i]) continue;
    const BaObservation& o = problem.observations[i];
    const Eigen::Vector2d projected = camera.project(problem.keyframes[o.keyframe].T_camera_world *
                                                     problem.points[o.point].position_world);
    sum += (o.pixel - projected).squaredNorm() * o.information;
    count += 2;
  }
  return std::sqrt(sum / count);
}

double max_pose_rotation_error(const BaProblem& a, const BaProblem& b) {
  double worst = 0.0;
  for (size_t k = 0; k < a.keyframes.size(); ++k) {
    worst = std::max(
        worst, rotation_error_deg(a.keyframes[k].T_camera_world, b.keyframes[k].T_camera_world));
  }
  return worst;
}

double max_pose_translation_error(const BaProblem& a, const BaProblem& b) {
  double worst = 0.0;
  for (size_t k = 0; k < a.keyframes.size(); ++k) {
    worst = std::max(
        worst, translation_error(a.keyframes[k].T_camera_world, b.keyframes[k].T_camera_world));
  }
  return worst;
}

void expect_ba_converges(double depth_fraction, double max_translation_error, uint32_t seed) {
  BaScene scene = make_scene(8, 2, 400, depth_fraction, 0.0, seed);
  const std::vector<uint8_t> all(scene.problem.observations.size(), 1);
  const double rms_before = rms_whitened_reprojection(scene.problem, all);
  const double rotation_before = max_pose_rotation_error(scene.problem, scene.truth);
  const BaProblem start = scene.problem;

  const PinholeCamera camera = test_camera();
  const BaResult result =
      solve_bundle_adjustment(scene.problem, camera, test_bf(camera), u_r_model_options());

  const double rms_after = rms_whitened_reprojection(scene.problem, result.observation_inlier);
  EXPECT_GT(rms_before, 5.0);
  EXPECT_LT(rms_after, 1.1);  // the noise level, σ = 1 after whitening
  EXPECT_GT(rms_after, 0.8);  // not over-fitted either
  EXPECT_LT(result.final_cost, 0.05 * result.initial_cost);
  EXPECT_GT(result.iterations, 0);
  EXPECT_FALSE(result.stopped_early);
  // The maximum-likelihood poses differ from the truth by the noise: with 1 px and the virtual
  // baseline, depth σ at 4 m is ≈ 0.4 m; the scale of the 1 m window rests on the two fixed
  // keyframes 15 cm apart, so errors of a few tenths of a degree / centimetres remain.
  EXPECT_LT(max_pose_rotation_error(scene.problem, scene.truth), 0.2);
  EXPECT_LT(max_pose_rotation_error(scene.problem, scene.truth), 0.25 * rotation_before);
  EXPECT_LT(max_pose_translation_error(scene.problem, scene.truth), max_translation_error);
  for (size_t k = 0; k < scene.problem.keyframes.size(); ++k) {
    if (!scene.problem.keyframes[k].fixed) continue;
    EXPECT_TRUE(
        scene.problem.keyframes[k].T_camera_world.isApprox(start.keyframes[k].T_camera_world, 0.0))
        << "fixed keyframe " << k << " moved";
  }
  const auto kept =
      std::count(result.observation_inlier.begin(), result.observation_inlier.end(), 1);
  EXPECT_GT(kept, 0.9 * static_cast<double>(result.observation_inlier.size()));
}

TEST(LocalBundleAdjustment, ExactMeasurementsRecoverTheTruth) {
  BaScene scene = make_scene(8, 2, 300, 0.5, 0.0, 10);
  const PinholeCamera camera = test_camera();
  const double bf = test_bf(camera);
  for (BaObservation& o : scene.problem.observations) {  // remove the noise
    const Eigen::Vector3d p = scene.truth.keyframes[o.keyframe].T_camera_world *
                              scene.truth.points[o.point].position_world;
    o.pixel = camera.project(p);
    if (!std::isnan(o.right_u)) o.right_u = o.pixel.x() - bf / p.z();
  }
  BaOptions options;
  options.refine_iterations = 30;
  const BaResult result = solve_bundle_adjustment(scene.problem, camera, bf, options);
  EXPECT_LT(max_pose_rotation_error(scene.problem, scene.truth), 1e-5);
  EXPECT_LT(max_pose_translation_error(scene.problem, scene.truth), 1e-6);
  // Points seen once without depth are free along their ray; all others must be exact.
  std::vector<int> constraints(scene.truth.points.size(), 0);
  for (const BaObservation& o : scene.problem.observations) {
    constraints[o.point] += std::isnan(o.right_u) ? 1 : 2;
  }
  double worst_point_error = 0.0;
  for (size_t p = 0; p < scene.truth.points.size(); ++p) {
    if (constraints[p] < 2) continue;
    worst_point_error = std::max(
        worst_point_error,
        (scene.problem.points[p].position_world - scene.truth.points[p].position_world).norm());
  }
  EXPECT_LT(worst_point_error, 1e-5);
  EXPECT_LT(result.final_cost, 1e-8);
}

TEST(LocalBundleAdjustment, RgbdObservationsConvergeToNoiseLevel) {
  expect_ba_converges(1.0, 0.02, 11);
}

TEST(LocalBundleAdjustment, MixedDepthObservationsConvergeToNoiseLevel) {
  expect_ba_converges(0.5, 0.02, 12);
}

TEST(LocalBundleAdjustment, MonocularObservationsConvergeToNoiseLevel) {
  expect_ba_converges(0.0, 0.03, 13);
}

TEST(LocalBundleAdjustment, FlagsOutlierObservations) {
  BaScene scene = make_scene(6, 2, 300, 0.7, 0.1, 14);
  const PinholeCamera camera = test_camera();
  const BaResult result =
      solve_bundle_adjustment(scene.problem, camera, test_bf(camera), u_r_model_options());
  int outliers = 0, flagged = 0, inliers = 0, kept = 0;
  for (size_t i = 0; i < scene.is_outlier.size(); ++i) {
    if (scene.is_outlier[i]) {
      ++outliers;
      flagged += result.observation_inlier[i] == 0;
    } else {
      ++inliers;
      kept += result.observation_inlier[i] == 1;
    }
  }
  EXPECT_GE(flagged, 0.97 * outliers) << flagged << "/" << outliers;
  EXPECT_GE(kept, 0.9 * inliers) << kept << "/" << inliers;
  EXPECT_LT(rms_whitened_reprojection(scene.problem, result.observation_inlier), 1.1);
  EXPECT_LT(max_pose_translation_error(scene.problem, scene.truth), 0.01);
}

TEST(LocalBundleAdjustment, AllKeyframesFixedOptimisesPointsOnly) {
  BaScene scene = make_scene(4, 4, 200, 1.0, 0.0, 15);
  const BaProblem start = scene.problem;
  const PinholeCamera camera = test_camera();
  const BaResult result =
      solve_bundle_adjustment(scene.problem, camera, test_bf(camera), u_r_model_options());
  for (size_t k = 0; k < 4; ++k) {
    EXPECT_TRUE(
        scene.problem.keyframes[k].T_camera_world.isApprox(start.keyframes[k].T_camera_world, 0.0));
  }
  EXPECT_LT(result.final_cost, 0.1 * result.initial_cost);
  EXPECT_LT(rms_whitened_reprojection(scene.problem, result.observation_inlier), 1.1);
}

TEST(LocalBundleAdjustment, StopRequestKeepsProgressAndSkipsSecondStage) {
  BaScene scene = make_scene(6, 2, 300, 1.0, 0.0, 16);
  const PinholeCamera camera = test_camera();
  BaOptions options;
  int polls = 0;
  options.should_stop = [&polls] { return ++polls >= 2; };
  const BaResult result = solve_bundle_adjustment(scene.problem, camera, test_bf(camera), options);
  EXPECT_TRUE(result.stopped_early);
  EXPECT_EQ(polls, 2);  // never polled again: stage 2 did not run
  EXPECT_LE(result.iterations, 2);
  EXPECT_LT(result.final_cost, result.initial_cost);
}

TEST(LocalBundleAdjustment, EmptyProblemIsANoOp) {
  BaProblem problem;
  problem.keyframes.push_back({7, Pose::Identity(), false});
  const PinholeCamera camera = test_camera();
  const BaResult result = solve_bundle_adjustment(problem, camera, test_bf(camera));
  EXPECT_TRUE(result.observation_inlier.empty());
  EXPECT_EQ(result.iterations, 0);
  EXPECT_TRUE(problem.keyframes[0].T_camera_world.isApprox(Pose::Identity(), 0.0));
}

TEST(LocalBundleAdjustment, RejectsObservationIndexingOutOfRange) {
  BaProblem problem;
  problem.keyframes.push_back({0, Pose::Identity(), false});
  problem.points.push_back({0, Eigen::Vector3d(0.0, 0.0, 2.0)});
  problem.observations.push_back({0, 3, {320.0, 240.0}, -1.0, 1.0});
  const PinholeCamera camera = test_camera();
  try {
    solve_bundle_adjustment(problem, camera, test_bf(camera));
    FAIL() << "expected pspslam::Error";
  } catch (const Error& error) {
    EXPECT_EQ(std::string(error.what()),
              "solve_bundle_adjustment: observation 0 references keyframe 0 of 1 / point 3 of 1");
  }
}

}  // namespace
}  // namespace pspslam
