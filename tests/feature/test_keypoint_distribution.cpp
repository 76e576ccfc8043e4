#include <gtest/gtest.h>

#include <vector>

#include "pspslam/feature/keypoint_distribution.h"

namespace pspslam {
namespace {

cv::KeyPoint keypoint_at(float x, float y, float response) {
  return cv::KeyPoint(cv::Point2f(x, y), 7.0f, -1.0f, response);
}

TEST(QuadtreeDistributor, KeepsEverythingWhenBelowTarget) {
  QuadtreeDistributor distributor;
  const std::vector<cv::KeyPoint> candidates = {keypoint_at(10, 10, 1), keypoint_at(50, 60, 2)};
  std::vector<cv::KeyPoint> selected;
  distributor.distribute(candidates, cv::Rect2f(0, 0, 100, 100), 5, selected);
  EXPECT_EQ(selected.size(), 2u);
  distributor.distribute(candidates, cv::Rect2f(0, 0, 100, 100), 0, selected);
  EXPECT_TRUE(selected.empty());
}

TEST(QuadtreeDistributor, SpreadsOverAreaInsteadOfTakingTheStrongestCluster) {
  // 400 strong keypoints crowd the top-left 20x20 corner, 100 weak ones lie on a regular grid
  // over the whole 200x200 area. A best-by-response pick would take only the cluster.
  std::vector<cv::KeyPoint> candidates;
  for (int y = 0; y < 20; ++y) {
    for (int x = 0; x < 20; ++x) candidates.push_back(keypoint_at(x, y, 100.0f + x + y));
  }
  for (int y = 0; y < 10; ++y) {
    for (int x = 0; x < 10; ++x) candidates.push_back(keypoint_at(5 + 20 * x, 5 + 20 * y, 1.0f));
  }
  QuadtreeDistributor distributor;
  std::vector<cv::KeyPoint> selected;
  distributor.distribute(candidates, cv::Rect2f(0, 0, 200, 200), 40, selected);
  ASSERT_EQ(selected.size(), 40u);
  int outside_cluster = 0;
  bool quadrant_seen[2][2] = {};
  for (const cv::KeyPoint& keypoint : selected) {
    outside_cluster += keypoint.pt.x >= 20 || keypoint.pt.y >= 20;
    quadrant_seen[keypoint.pt.y >= 100][keypoint.pt.x >= 100] = true;
  }
  EXPECT_GE(outside_cluster, 25);
  EXPECT_TRUE(quadrant_seen[0][0] && quadrant_seen[0][1] && quadrant_seen[1][0] &&
              quadrant_seen[1][1]);
}

TEST(QuadtreeDistributor, KeepsStrongestPerNodeAndIsDeterministic) {
  // Two keypoints in each 50x50 quadrant of a 100x100 area; target 4 -> one per quadrant, the
  // stronger one.
  const std::vector<cv::KeyPoint> candidates = {keypoint_at(10, 10, 5), keypoint_at(20, 20, 9),
                                                keypoint_at(70, 10, 3), keypoint_at(80, 20, 1),
                                                keypoint_at(10, 70, 4), keypoint_at(20, 80, 8),
                                                keypoint_at(70, 70, 7), keypoint_at(80, 80, 2)};
  QuadtreeDistributor distributor;
  std::vector<cv::KeyPoint> selected;
  distributor.distribute(candidates, cv::Rect2f(0, 0, 100, 100), 4, selected);
  ASSERT_EQ(selected.size(), 4u);
  float response_sum = 0.0f;
  for (const cv::KeyPoint& keypoint : selected) response_sum += keypoint.response;
  EXPECT_FLOAT_EQ(response_sum, 9 + 3 + 8 + 7);

  std::vector<cv::KeyPoint> again;
  distributor.distribute(candidates, cv::Rect2f(0, 0, 100, 100), 4, again);
  ASSERT_EQ(again.size(), selected.size());
  for (std::size_t i = 0; i < again.size(); ++i) EXPECT_EQ(again[i].pt, selected[i].pt);
}

TEST(ShareFeatureBudget, ShortLevelsKeepWhatTheyHaveAndTheRestGoesToLevelsWithCorners) {
  // The default shares of 1000 features on 8 levels; levels 3-7 have fewer corners than that.
  const std::vector<int> shares{217, 181, 151, 126, 105, 87, 73, 60};
  const std::vector<int> available{5000, 260, 900, 40, 30, 0, 12, 7};
  std::vector<int> budgets(shares.size(), -1);
  share_feature_budget(shares, available, budgets);
  int total = 0;
  for (std::size_t l = 0; l < shares.size(); ++l) {
    EXPECT_LE(budgets[l], available[l]) << l;
    total += budgets[l];
  }
  EXPECT_EQ(total, 1000);
  // Short levels keep all they have; level 1 is capped by its 260 corners; the 326 features that
  // levels 1 and 3-7 cannot use (1000 - 674 after the first round) go to levels 0, 1 and 2.
  EXPECT_EQ(budgets[3], 40);
  EXPECT_EQ(budgets[4], 30);
  EXPECT_EQ(budgets[5], 0);
  EXPECT_EQ(budgets[6], 12);
  EXPECT_EQ(budgets[7], 7);
  EXPECT_EQ(budgets[1], 260);
  EXPECT_GT(budgets[0], shares[0]);
  EXPECT_GT(budgets[2], shares[2]);
  // Level 0 has the larger share, so it takes the larger part of what is left.
  EXPECT_GT(budgets[0] - shares[0], budgets[2] - shares[2]);
}

TEST(ShareFeatureBudget, UnchangedWhenEveryLevelCanFillItsShareAndCappedByWhatExists) {
  const std::vector<int> shares{217, 181, 151, 126, 105, 87, 73, 60};
  std::vector<int> budgets(shares.size());
  share_feature_budget(shares, std::vector<int>(shares.size(), 10000), budgets);
  EXPECT_EQ(budgets, shares);
  // Fewer corners than features in total: every level takes all it has.
  const std::vector<int> few{100, 90, 80, 70, 60, 50, 40, 30};
  share_feature_budget(shares, few, budgets);
  EXPECT_EQ(budgets, few);
  // A single spare feature is not lost to rounding.
  const std::vector<int> almost{217, 181, 151, 126, 105, 87, 73, 59};
  std::vector<int> more = almost;
  more[0] += 1;
  share_feature_budget(shares, more, budgets);
  EXPECT_EQ(budgets, more);
}

}  // namespace
}  // namespace pspslam
