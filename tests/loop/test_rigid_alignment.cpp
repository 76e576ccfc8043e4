#include "pspslam/solve/rigid_alignment.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <random>

namespace pspslam {
namespace {

Pose known_transform() {
  Pose T = Pose::Identity();
  T.linear() =
      Eigen::AngleAxisd(0.4, Eigen::Vector3d(0.2, 1.0, -0.3).normalized()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(0.35, -0.12, 0.8);
  return T;
}

double rotation_error_deg(const Pose& a, const Pose& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle() * 180.0 / M_PI;
}

TEST(RigidAlignment, ClosedFormIsExactOnNoiseFreePoints) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> uniform(-2.0, 2.0);
  const Pose T = known_transform();
  std::vector<Eigen::Vector3d> source;
  std::vector<Eigen::Vector3d> target;
  for (int i = 0; i < 10; ++i) {
    source.emplace_back(uniform(rng), uniform(rng), 3.0 + uniform(rng));
    target.push_back(T * source.back());
  }
  const auto estimate = align_rigid(source, target);
  ASSERT_TRUE(estimate.has_value());
  EXPECT_LT((estimate->translation() - T.translation()).norm(), 1e-9);
  EXPECT_LT(rotation_error_deg(*estimate, T), 1e-7);
  EXPECT_GT(estimate->linear().determinant(), 0.0) << "a rotation, never a reflection";
}

TEST(RigidAlignment, DegenerateInputIsRefused) {
  const std::vector<Eigen::Vector3d> line{{0, 0, 1}, {0, 0, 2}, {0, 0, 3}, {0, 0, 4}};
  EXPECT_FALSE(align_rigid(line, line).has_value()) << "collinear points leave a rotation free";
  const std::vector<Eigen::Vector3d> two{{0, 0, 1}, {1, 0, 2}};
  EXPECT_FALSE(align_rigid(two, two).has_value());
  const std::vector<Eigen::Vector3d> three{{0, 0, 1}, {1, 0, 2}, {0, 1, 2}};
  EXPECT_FALSE(align_rigid(three, two).has_value()) << "sizes differ";
}

// 150 matched map points (depth 1-5 m, 1 cm noise) of which 40% are wrong matches: RANSAC must
// find the transform to millimetres and label the outliers.
TEST(RigidAlignment, RansacRecoversTransformWithOutliers) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> uniform(-1.5, 1.5);
  std::normal_distribution<double> noise(0.0, 0.01);
  const Pose T = known_transform();
  std::vector<RigidCorrespondence> correspondences;
  std::vector<bool> is_outlier;
  for (int i = 0; i < 150; ++i) {
    RigidCorrespondence c;
    c.source = Eigen::Vector3d(uniform(rng), uniform(rng), 3.0 + uniform(rng));
    const bool outlier = i % 5 < 2;
    c.target = outlier ? Eigen::Vector3d(uniform(rng), uniform(rng), 3.0 + uniform(rng))
                       : T * c.source + Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    c.max_error = 0.05;
    correspondences.push_back(c);
    is_outlier.push_back(outlier);
  }
  const RigidRansacResult result = solve_rigid_ransac(correspondences);
  ASSERT_TRUE(result.success);
  EXPECT_EQ(result.S_target_source.scale, 1.0);
  EXPECT_LT((result.S_target_source.translation - T.translation()).norm(), 0.005);
  EXPECT_LT(rotation_error_deg(result.S_target_source.rescaled_pose(), T), 0.2);
  int wrong_labels = 0;
  for (size_t i = 0; i < correspondences.size(); ++i) {
    wrong_labels += (result.inlier[i] != 0) == is_outlier[i] ? 1 : 0;
  }
  EXPECT_EQ(result.num_inliers, 90);
  // A random outlier lands within 5 cm of its prediction with probability ~1e-4.
  EXPECT_EQ(wrong_labels, 0);
  EXPECT_LT(result.iterations, 300) << "the adaptive stop should end well before the budget";
}

// Monocular loops: the two sides of the loop disagree in scale as well. The closed form recovers
// a known scale exactly; the RANSAC with estimate_scale recovers it among 40 % outliers, with an
// inlier threshold relative to the depth as the monocular loop detector sets it.
TEST(RigidAlignment, SimilarityRecoversAKnownScale) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> uniform(-1.5, 1.5);
  std::normal_distribution<double> noise(0.0, 0.004);
  const Pose T = known_transform();
  const Sim3 S(T.linear(), T.translation(), 0.62);
  std::vector<Eigen::Vector3d> source;
  std::vector<Eigen::Vector3d> target;
  for (int i = 0; i < 10; ++i) {
    source.emplace_back(uniform(rng), uniform(rng), 3.0 + uniform(rng));
    target.push_back(S * source.back());
  }
  const auto exact = align_similarity(source, target);
  ASSERT_TRUE(exact.has_value());
  EXPECT_NEAR(exact->scale, 0.62, 1e-9);
  EXPECT_LT((exact->translation - S.translation).norm(), 1e-9);
  const auto rigid = align_rigid(source, target);
  ASSERT_TRUE(rigid.has_value());
  EXPECT_GT((*rigid * source[0] - target[0]).norm(), 0.1) << "without scale it cannot fit";

  std::vector<RigidCorrespondence> correspondences;
  std::vector<bool> is_outlier;
  for (int i = 0; i < 150; ++i) {
    RigidCorrespondence c;
    c.source = Eigen::Vector3d(uniform(rng), uniform(rng), 3.0 + uniform(rng));
    const bool outlier = i % 5 < 2;
    c.target = outlier ? Eigen::Vector3d(uniform(rng), uniform(rng), 2.0 + uniform(rng))
                       : S * c.source + Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    c.max_error = 0.03 * std::max(c.target.z(), 0.1);
    correspondences.push_back(c);
    is_outlier.push_back(outlier);
  }
  RigidRansacOptions options;
  options.estimate_scale = true;
  const RigidRansacResult result = solve_rigid_ransac(correspondences, options);
  ASSERT_TRUE(result.success);
  EXPECT_NEAR(result.S_target_source.scale, 0.62, 0.01);
  EXPECT_LT(rotation_error_deg(result.S_target_source.rescaled_pose(), T), 0.5);
  int wrong_labels = 0;
  for (size_t i = 0; i < correspondences.size(); ++i) {
    wrong_labels += (result.inlier[i] != 0) == is_outlier[i] ? 1 : 0;
  }
  EXPECT_LE(wrong_labels, 2);
  // The same pairs without a scale: no rigid motion explains them.
  EXPECT_FALSE(solve_rigid_ransac(correspondences).success);
}

TEST(RigidAlignment, RansacFailsWithoutEnoughInliers) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> uniform(-1.5, 1.5);
  std::vector<RigidCorrespondence> correspondences;
  for (int i = 0; i < 60; ++i) {
    RigidCorrespondence c;
    c.source = Eigen::Vector3d(uniform(rng), uniform(rng), 3.0 + uniform(rng));
    c.target = Eigen::Vector3d(uniform(rng), uniform(rng), 3.0 + uniform(rng));
    c.max_error = 0.03;
    correspondences.push_back(c);
  }
  const RigidRansacResult result = solve_rigid_ransac(correspondences);
  EXPECT_FALSE(result.success) << result.num_inliers << " inliers among random pairs";
  EXPECT_LT(result.num_inliers, 20);
}

}  // namespace
}  // namespace pspslam
