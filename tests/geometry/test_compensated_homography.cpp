#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

#include "pspslam/core/error.h"
#include "pspslam/core/yaml_section.h"
#include "pspslam/geometry/compensated_homography.h"

namespace pspslam {
namespace {

Eigen::Matrix3d true_homography() {
  Eigen::Matrix3d H;
  H << 1.02, 0.03, 6.5,   //
      -0.02, 0.99, -4.0,  //
      2e-5, -1e-5, 1.0;
  return H;
}

struct Correspondences {
  std::vector<Eigen::Vector2d> previous, current;
  std::vector<bool> outlier;
};

Correspondences make_correspondences(int count, double noise_px, double outlier_fraction,
                                     std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 640.0), v(0.0, 480.0), coin(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, noise_px);
  Correspondences c;
  const Eigen::Matrix3d H = true_homography();
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector2d x(u(rng), v(rng));
    Eigen::Vector2d y = transfer_point(H, x) + Eigen::Vector2d(noise(rng), noise(rng));
    const bool outlier = coin(rng) < outlier_fraction;
    if (outlier) y = Eigen::Vector2d(u(rng), v(rng));
    c.previous.push_back(x + Eigen::Vector2d(noise(rng), noise(rng)));
    c.current.push_back(y);
    c.outlier.push_back(outlier);
  }
  return c;
}

// Mean distance between where H and the true homography send a grid of image points.
double grid_error(const Eigen::Matrix3d& H) {
  double sum = 0.0;
  int count = 0;
  for (int y = 0; y <= 480; y += 40) {
    for (int x = 0; x <= 640; x += 40) {
      const Eigen::Vector2d p(x, y);
      sum += (transfer_point(H, p) - transfer_point(true_homography(), p)).norm();
      ++count;
    }
  }
  return sum / count;
}

TEST(CompensatedHomography, RefinementBeatsRansacAndRejectsOutliers) {
  int refined_better = 0;
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    const Correspondences c = make_correspondences(300, 0.5, 0.3, seed);
    const CompensatedHomography h = estimate_compensated_homography(
        std::span<const Eigen::Vector2d>(c.previous), std::span<const Eigen::Vector2d>(c.current),
        HomographyParams{});
    ASSERT_TRUE(h.valid);
    // Eq. 11 is what LM minimises, so its value over the same inliers can only go down.
    EXPECT_LT(h.rms_after_px, h.rms_before_px);
    // Noise of 0.5 px on both points: the optimal transfer RMS is about 0.5 * 2 = 1 px.
    EXPECT_LT(h.rms_after_px, 1.1);
    const double before = grid_error(h.H_ransac);
    const double after = grid_error(h.H);
    EXPECT_LT(after, 0.5) << "seed " << seed;
    if (after < before) ++refined_better;
    int outliers_accepted = 0, inliers_rejected = 0;
    for (size_t i = 0; i < c.outlier.size(); ++i) {
      if (c.outlier[i] && h.inliers[i]) ++outliers_accepted;
      if (!c.outlier[i] && !h.inliers[i]) ++inliers_rejected;
    }
    // Random outliers land within 2 px of the true transfer with probability ~ 4*pi/(640*480).
    EXPECT_LE(outliers_accepted, 1) << "seed " << seed;
    // 2 px threshold vs ~0.7 px noise per axis: P(error > 2 px) = exp(-4) ~ 2%.
    EXPECT_LT(inliers_rejected, 0.06 * 300) << "seed " << seed;
  }
  EXPECT_GE(refined_better, 9);
}

TEST(CompensatedHomography, ExactDataIsRecoveredExactly) {
  const Correspondences c = make_correspondences(50, 0.0, 0.0, 3);
  const CompensatedHomography h = estimate_compensated_homography(
      std::span<const Eigen::Vector2d>(c.previous), std::span<const Eigen::Vector2d>(c.current),
      HomographyParams{});
  ASSERT_TRUE(h.valid);
  EXPECT_EQ(h.inlier_count, 50);
  EXPECT_LT(grid_error(h.H), 1e-6);
  EXPECT_LT(h.rms_after_px, 1e-6);
}

TEST(CompensatedHomography, TooFewOrMismatchedPoints) {
  const std::vector<Eigen::Vector2d> three = {{0, 0}, {1, 0}, {0, 1}};
  EXPECT_FALSE(estimate_compensated_homography(std::span<const Eigen::Vector2d>(three),
                                               std::span<const Eigen::Vector2d>(three),
                                               HomographyParams{})
                   .valid);
  const std::vector<Eigen::Vector2d> four = {{0, 0}, {1, 0}, {0, 1}, {1, 1}};
  try {
    estimate_compensated_homography(std::span<const Eigen::Vector2d>(three),
                                    std::span<const Eigen::Vector2d>(four), HomographyParams{});
    FAIL() << "expected Error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(),
                 "estimate_compensated_homography: 3 previous points but 4 current points");
  }
}

TEST(CompensatedHomography, CvPointOverloadAndWarp) {
  const Correspondences c = make_correspondences(100, 0.0, 0.0, 5);
  std::vector<cv::Point2f> x, y;
  for (size_t i = 0; i < c.previous.size(); ++i) {
    x.emplace_back(c.previous[i].x(), c.previous[i].y());
    y.emplace_back(c.current[i].x(), c.current[i].y());
  }
  const CompensatedHomography h = estimate_compensated_homography(
      std::span<const cv::Point2f>(x), std::span<const cv::Point2f>(y), HomographyParams{});
  ASSERT_TRUE(h.valid);
  EXPECT_LT(grid_error(h.H), 1e-3);  // float input precision

  // A label map warped with nearest neighbour keeps only its own label values.
  cv::Mat labels = cv::Mat::zeros(480, 640, CV_8UC1);
  labels(cv::Rect(200, 150, 100, 80)).setTo(15);
  labels(cv::Rect(320, 300, 40, 40)).setTo(100);
  const cv::Mat warped = warp_to_current(labels, h.H, labels.size(), true);
  for (int v = 0; v < warped.rows; ++v)
    for (int u = 0; u < warped.cols; ++u) {
      const int value = warped.at<std::uint8_t>(v, u);
      ASSERT_TRUE(value == 0 || value == 15 || value == 100) << value;
    }
  // The centre of the person box moves where the homography sends it.
  const Eigen::Vector2d centre = transfer_point(true_homography(), Eigen::Vector2d(250, 190));
  EXPECT_EQ(warped.at<std::uint8_t>(static_cast<int>(centre.y()), static_cast<int>(centre.x())),
            15);
  std::vector<Eigen::Vector2d> projected;
  transfer_points(h.H, std::span<const Eigen::Vector2d>(c.previous), projected);
  ASSERT_EQ(projected.size(), c.previous.size());
  EXPECT_LT((projected[0] - c.current[0]).norm(), 1e-3);
}

TEST(CompensatedHomography, ParamsFromYamlNameTheKey) {
  const YAML::Node ok = YAML::Load("inlier_threshold_px: 1.5\nlm_max_iterations: 5\n");
  YamlSection section(ok, "geometry.yaml", "geometry.homography");
  const HomographyParams p = HomographyParams::from_yaml(section);
  EXPECT_DOUBLE_EQ(p.inlier_threshold_px, 1.5);
  EXPECT_EQ(p.lm_max_iterations, 5);

  const YAML::Node bad = YAML::Load("inlier_threshold_px: -1\n");
  YamlSection bad_section(bad, "geometry.yaml", "geometry.homography");
  try {
    HomographyParams::from_yaml(bad_section);
    FAIL() << "expected Error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(),
                 "geometry.yaml:1: key 'geometry.homography.inlier_threshold_px' must be > 0");
  }
  const YAML::Node typo = YAML::Load("inlier_treshold_px: 2\n");
  YamlSection typo_section(typo, "geometry.yaml", "geometry.homography");
  try {
    HomographyParams::from_yaml(typo_section);
    FAIL() << "expected Error";
  } catch (const Error& e) {
    EXPECT_STREQ(
        e.what(),
        "geometry.yaml:1: unknown key 'geometry.homography.inlier_treshold_px' (did you mean "
        "'geometry.homography.inlier_threshold_px'?)");
  }
}

}  // namespace
}  // namespace pspslam
