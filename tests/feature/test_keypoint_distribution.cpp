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

}  // namespace
}  // namespace pspslam
