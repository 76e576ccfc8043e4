#include "pspslam/solve/two_view_initializer.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace pspslam {
namespace {

struct TwoViews {
  std::vector<Eigen::Vector2d> first;
  std::vector<Eigen::Vector2d> second;
  std::vector<Eigen::Vector3d> points;  // first camera's frame; only for the inliers
  std::vector<bool> outlier;
};

enum class Scene { planar, general };

// Points in front of the first camera (a tilted plane 3 m away, or a volume 2-6 m deep), seen
// from a second camera T_second_first, with Gaussian pixel noise and a share of correspondences
// replaced by random pixels.
TwoViews render(const PinholeCamera& camera, Scene scene, const Pose& T_second_first,
                double noise_px, double outlier_share, std::uint64_t seed) {
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, noise_px);
  TwoViews views;
  while (views.first.size() < 300) {
    const double x = -2.0 + 4.0 * u01(random);
    const double y = -1.5 + 3.0 * u01(random);
    const double z = scene == Scene::planar ? 3.0 + 0.3 * x - 0.2 * y : 2.0 + 4.0 * u01(random);
    const Eigen::Vector3d X(x * z / 3.0, y * z / 3.0, z);
    const Eigen::Vector2d p1 = camera.project(X);
    const Eigen::Vector3d X2 = T_second_first * X;
    if (X2.z() <= 0.0) continue;
    const Eigen::Vector2d p2 = camera.project(X2);
    if (!camera.in_image(p1, 5.0) || !camera.in_image(p2, 5.0)) continue;
    const bool outlier = u01(random) < outlier_share;
    views.first.push_back(p1 + Eigen::Vector2d(noise(random), noise(random)));
    views.second.push_back(
        outlier ? Eigen::Vector2d(camera.width * u01(random), camera.height * u01(random))
                : p2 + Eigen::Vector2d(noise(random), noise(random)));
    views.points.push_back(X);
    views.outlier.push_back(outlier);
  }
  return views;
}

Pose motion() {
  Pose T = Pose::Identity();
  T.linear() = Eigen::AngleAxisd(3.0 * M_PI / 180.0, Eigen::Vector3d(0.2, 1.0, 0.1).normalized())
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(0.3, 0.05, 0.02);
  return T;
}

double rotation_error_deg(const Pose& estimate, const Pose& truth) {
  return Eigen::AngleAxisd(estimate.linear() * truth.linear().transpose()).angle() * 180.0 / M_PI;
}

double direction_error_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) * 180.0 / M_PI;
}

// Median |X_est * |t| - X_true| / |X_true| over the triangulated inliers: the points are right up
// to the unknown scale, which the true baseline fixes.
double median_point_error(const TwoViewResult& result, const TwoViews& views, double baseline) {
  std::vector<double> errors;
  for (size_t i = 0; i < views.points.size(); ++i) {
    if (!result.triangulated[i] || views.outlier[i]) continue;
    errors.push_back((result.points[i] * baseline - views.points[i]).norm() /
                     views.points[i].norm());
  }
  if (errors.empty()) return 1e9;
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  return errors[errors.size() / 2];
}

class TwoViewScenes : public ::testing::TestWithParam<std::uint64_t> {};

TEST_P(TwoViewScenes, GeneralSceneChoosesFundamentalAndRecoversTheMotion) {
  const PinholeCamera camera;
  const Pose truth = motion();
  const TwoViews views = render(camera, Scene::general, truth, 0.5, 0.1, GetParam());
  TwoViewOptions options;
  options.seed = GetParam();
  const TwoViewResult result = initialize_two_view(camera, views.first, views.second, options);
  ASSERT_TRUE(result.success) << result.failure;
  EXPECT_EQ(result.model, TwoViewModel::fundamental);
  EXPECT_LT(result.homography_ratio, 0.45);
  EXPECT_LT(rotation_error_deg(result.T_second_first, truth), 0.5);
  EXPECT_LT(direction_error_deg(result.T_second_first.translation(), truth.translation()), 2.0);
  EXPECT_NEAR(result.T_second_first.translation().norm(), 1.0, 1e-9);
  EXPECT_GT(result.num_triangulated, 150);
  EXPECT_GE(result.parallax_deg, 1.0);
  EXPECT_LT(median_point_error(result, views, truth.translation().norm()), 0.03);
  // An outlier survives only where its random pixel happens to fall within ~2 px of its
  // epipolar line (about 1 % of them).
  int outliers_triangulated = 0;
  for (size_t i = 0; i < views.outlier.size(); ++i) {
    outliers_triangulated += views.outlier[i] && result.triangulated[i] ? 1 : 0;
  }
  EXPECT_LE(outliers_triangulated, 2);
}

TEST_P(TwoViewScenes, PlanarSceneChoosesHomographyAndRecoversTheMotion) {
  const PinholeCamera camera;
  const Pose truth = motion();
  const TwoViews views = render(camera, Scene::planar, truth, 0.5, 0.1, GetParam());
  TwoViewOptions options;
  options.seed = GetParam();
  const TwoViewResult result = initialize_two_view(camera, views.first, views.second, options);
  ASSERT_TRUE(result.success) << result.failure;
  EXPECT_EQ(result.model, TwoViewModel::homography);
  EXPECT_GT(result.homography_ratio, 0.45);
  EXPECT_LT(rotation_error_deg(result.T_second_first, truth), 0.5);
  EXPECT_LT(direction_error_deg(result.T_second_first.translation(), truth.translation()), 2.0);
  EXPECT_GT(result.num_triangulated, 150);
  EXPECT_LT(median_point_error(result, views, truth.translation().norm()), 0.03);
}

INSTANTIATE_TEST_SUITE_P(Seeds, TwoViewScenes, ::testing::Values(1u, 2u, 3u));

TEST(TwoViewInitializer, SequentialFitGivesTheParallelResult) {
  const PinholeCamera camera;
  const TwoViews views = render(camera, Scene::general, motion(), 0.5, 0.1, 7);
  TwoViewOptions options;
  const TwoViewResult parallel = initialize_two_view(camera, views.first, views.second, options);
  options.parallel = false;
  const TwoViewResult sequential = initialize_two_view(camera, views.first, views.second, options);
  ASSERT_TRUE(parallel.success);
  EXPECT_EQ(parallel.score_homography, sequential.score_homography);
  EXPECT_EQ(parallel.score_fundamental, sequential.score_fundamental);
  EXPECT_TRUE(parallel.T_second_first.isApprox(sequential.T_second_first));
}

TEST(TwoViewInitializer, PureRotationIsRefused) {
  const PinholeCamera camera;
  Pose rotation = motion();
  rotation.translation().setZero();
  const TwoViews views = render(camera, Scene::general, rotation, 0.5, 0.0, 4);
  const TwoViewResult result = initialize_two_view(camera, views.first, views.second);
  EXPECT_FALSE(result.success);
  // A rotation maps every pixel by one homography: H explains it, but without a baseline.
  EXPECT_EQ(result.model, TwoViewModel::homography);
  EXPECT_FALSE(result.failure.empty());
}

TEST(TwoViewInitializer, SmallBaselineIsRefusedForParallax) {
  const PinholeCamera camera;
  Pose small = motion();
  small.translation() = Eigen::Vector3d(0.01, 0.0, 0.0);  // 1 cm at 2-6 m: < 0.3 deg
  const TwoViews views = render(camera, Scene::general, small, 0.3, 0.0, 5);
  const TwoViewResult result = initialize_two_view(camera, views.first, views.second);
  EXPECT_FALSE(result.success);
  EXPECT_LT(result.parallax_deg, 1.0);
}

TEST(TwoViewInitializer, TooFewCorrespondences) {
  const PinholeCamera camera;
  const std::vector<Eigen::Vector2d> seven(7, Eigen::Vector2d(100.0, 100.0));
  const TwoViewResult result = initialize_two_view(camera, seven, seven);
  EXPECT_FALSE(result.success);
  EXPECT_EQ(result.failure, "fewer than 8 correspondences");
}

}  // namespace
}  // namespace pspslam
