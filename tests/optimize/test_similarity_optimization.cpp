#include "pspslam/optimize/similarity_optimization.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <vector>

#include "pspslam/solve/rigid_alignment.h"

namespace pspslam {
namespace {

// Two keyframes of a monocular loop: B (the loop side) and A (the current keyframe) 0.1 units
// apart, A's map 5 % larger than B's (scale drift). Each keyframe's map points carry the error a
// triangulated point has: 1 px on the bearing, 10 % on the depth.
struct TwoViews {
  PinholeCamera camera;
  Sim3 S_a_b_true;
  std::vector<SimilarityPair> pairs;
};

TwoViews make_views(double outlier_fraction, std::uint32_t seed) {
  TwoViews views;
  std::mt19937 rng(seed);
  std::normal_distribution<double> pixel_noise(0.0, 1.0);
  std::normal_distribution<double> depth_noise(0.0, 0.10);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(0.2, Eigen::Vector3d(0.1, 1.0, 0.2).normalized()).toRotationMatrix();
  views.S_a_b_true = Sim3(rotation, Eigen::Vector3d(0.08, -0.02, 0.05), 1.05);
  const PinholeCamera& camera = views.camera;
  const auto noisy_pixel = [&](const Eigen::Vector3d& point) {
    return Eigen::Vector2d(camera.project(point) +
                           Eigen::Vector2d(pixel_noise(rng), pixel_noise(rng)));
  };
  const auto triangulated = [&](const Eigen::Vector2d& pixel, double depth) {
    return camera.unproject(pixel, depth * (1.0 + depth_noise(rng)));
  };
  while (views.pairs.size() < 150) {
    const Eigen::Vector3d in_b = camera.unproject(
        Eigen::Vector2d(640.0 * uniform(rng), 480.0 * uniform(rng)), 2.0 + 3.0 * uniform(rng));
    const Eigen::Vector3d in_a = views.S_a_b_true * in_b;
    const Eigen::Vector2d pixel_a = camera.project(in_a);
    if (in_a.z() <= 0.0 || pixel_a.x() < 0 || pixel_a.x() >= 640 || pixel_a.y() < 0 ||
        pixel_a.y() >= 480)
      continue;
    SimilarityPair pair;
    pair.pixel_in_a = noisy_pixel(in_a);
    pair.pixel_in_b = noisy_pixel(in_b);
    pair.in_a = triangulated(noisy_pixel(in_a), in_a.z());
    pair.in_b = triangulated(noisy_pixel(in_b), in_b.z());
    if (uniform(rng) < outlier_fraction) {  // a wrong match: 30-80 px off, any direction
      const double angle = 2.0 * M_PI * uniform(rng);
      pair.pixel_in_a +=
          (30.0 + 50.0 * uniform(rng)) * Eigen::Vector2d(std::cos(angle), std::sin(angle));
    }
    views.pairs.push_back(pair);
  }
  return views;
}

double rotation_error_deg(const Sim3& a, const Sim3& b) {
  return Eigen::AngleAxisd(a.rotation * b.rotation.transpose()).angle() * 180.0 / M_PI;
}

// Where B's camera centre lands in A's camera (the loop correction moves the current keyframe
// by what this gets wrong).
double centre_error(const Sim3& estimate, const Sim3& truth) {
  return (estimate.translation - truth.translation).norm();
}

Sim3 three_d_fit(const TwoViews& views) {
  std::vector<Eigen::Vector3d> source;
  std::vector<Eigen::Vector3d> target;
  for (const SimilarityPair& pair : views.pairs) {
    source.push_back(pair.in_b);
    target.push_back(pair.in_a);
  }
  return *align_similarity(source, target);
}

// The 3D fit on depth-noisy points is biased (Umeyama's scale shrinks with the noise on the
// source side) and puts the camera off along the depth; reprojection recovers both.
TEST(SimilarityOptimization, RecoversWhatA3dFitOfDepthNoisyPointsMisses) {
  const TwoViews views = make_views(0.0, 7);
  const Sim3 fit = three_d_fit(views);
  const SimilarityOptimizationResult refined = optimize_similarity(views.camera, fit, views.pairs);
  const double fit_scale_error = std::abs(fit.scale - views.S_a_b_true.scale);
  const double refined_scale_error = std::abs(refined.S_a_b.scale - views.S_a_b_true.scale);
  RecordProperty("fit_scale_x1000", static_cast<int>(1000 * fit.scale));
  RecordProperty("refined_scale_x1000", static_cast<int>(1000 * refined.S_a_b.scale));
  RecordProperty("fit_centre_error_mm",
                 static_cast<int>(1000 * centre_error(fit, views.S_a_b_true)));
  RecordProperty("refined_centre_error_mm",
                 static_cast<int>(1000 * centre_error(refined.S_a_b, views.S_a_b_true)));
  EXPECT_LT(refined_scale_error, 0.01);
  EXPECT_LT(refined_scale_error, 0.25 * fit_scale_error);
  EXPECT_LT(centre_error(refined.S_a_b, views.S_a_b_true),
            0.25 * centre_error(fit, views.S_a_b_true));
  EXPECT_LT(rotation_error_deg(refined.S_a_b, views.S_a_b_true), 0.2);
  // 1 px keypoint noise in both images and the other image's depth error: about a third of
  // the pairs exceed χ² = 10 somewhere; most remain.
  EXPECT_GE(refined.num_inliers, 90);
}

// Pairs whose keypoint in A is a wrong match are rejected (χ² in either image), and the rest
// still give the transform.
TEST(SimilarityOptimization, RejectsPairsThatDoNotReproject) {
  const TwoViews views = make_views(0.2, 11);
  const SimilarityOptimizationResult refined =
      optimize_similarity(views.camera, three_d_fit(views), views.pairs);
  int wrong_accepted = 0;
  int right_rejected = 0;
  for (std::size_t k = 0; k < views.pairs.size(); ++k) {
    const SimilarityPair& pair = views.pairs[k];
    const bool wrong =
        (views.camera.project(views.S_a_b_true * pair.in_b) - pair.pixel_in_a).norm() > 30.0;
    if (wrong && refined.inlier[k]) ++wrong_accepted;
    if (!wrong && !refined.inlier[k]) ++right_rejected;
  }
  EXPECT_EQ(wrong_accepted, 0);
  EXPECT_LT(right_rejected, 50);
  EXPECT_LT(std::abs(refined.S_a_b.scale - views.S_a_b_true.scale), 0.01);
}

// RGB-D and stereo: the scale is given and stays.
TEST(SimilarityOptimization, KeepsTheScaleWhenNotEstimated) {
  const TwoViews views = make_views(0.0, 3);
  Sim3 initial = three_d_fit(views);
  initial.scale = 1.0;
  SimilarityOptimizationOptions options;
  options.estimate_scale = false;
  const SimilarityOptimizationResult refined =
      optimize_similarity(views.camera, initial, views.pairs, options);
  EXPECT_EQ(refined.S_a_b.scale, 1.0);
}

}  // namespace
}  // namespace pspslam
