#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include <cstdint>
#include <vector>

#include "pspslam/dynamic/keypoint_fusion.h"
#include "pspslam/semantic/segmenter.h"

namespace pspslam {
namespace {

// A person (label 15) occupying x in [100, 140), y in [100, 200) of a 320 x 240 label map.
cv::Mat person_labels() {
  cv::Mat labels = cv::Mat::zeros(240, 320, CV_8UC1);
  labels(cv::Rect(100, 100, 40, 100)).setTo(15);
  return labels;
}

std::vector<cv::KeyPoint> keypoints_at(const std::vector<cv::Point2f>& points) {
  std::vector<cv::KeyPoint> keypoints;
  for (const auto& p : points) keypoints.emplace_back(p, 31.0f);
  return keypoints;
}

TEST(KeypointFusion, SemanticMaskMarginCatchesSilhouetteFeatures) {
  // Inside the person, 3 px right of its edge, 20 px right of its edge.
  const auto keypoints = keypoints_at({{120, 150}, {142, 150}, {160, 150}});
  std::vector<std::uint8_t> flags;

  const cv::Mat no_margin = dynamic_mask(person_labels(), {15}, 0);
  EXPECT_EQ(fuse_keypoint_flags(keypoints, no_margin, {}, flags), 1);
  EXPECT_EQ(flags, (std::vector<std::uint8_t>{1, 0, 0}));

  const cv::Mat margin5 = dynamic_mask(person_labels(), {15}, 5);
  EXPECT_EQ(fuse_keypoint_flags(keypoints, margin5, {}, flags), 2);
  EXPECT_EQ(flags, (std::vector<std::uint8_t>{1, 1, 0}));
}

TEST(KeypointFusion, GeometryFlagsAddMovingObjectsOfStaticClasses) {
  // The third keypoint is on a carried box (a static class): only geometry knows it moves.
  const auto keypoints = keypoints_at({{120, 150}, {10, 10}, {250, 50}});
  const std::vector<std::uint8_t> geometry = {0, 0, 1};
  std::vector<std::uint8_t> flags;
  EXPECT_EQ(fuse_keypoint_flags(keypoints, dynamic_mask(person_labels(), {15}, 0), geometry, flags),
            2);
  EXPECT_EQ(flags, (std::vector<std::uint8_t>{1, 0, 1}));
  // Without a semantic mask (geometry-only mode) only the geometry verdict counts.
  EXPECT_EQ(fuse_keypoint_flags(keypoints, cv::Mat(), geometry, flags), 1);
  EXPECT_THROW(fuse_keypoint_flags(keypoints, cv::Mat(), std::vector<std::uint8_t>{1}, flags),
               std::exception);
}

TEST(KeypointFusion, DynamicKeypointsAreRemovedWithTheirDescriptors) {
  auto keypoints = keypoints_at({{1, 1}, {2, 2}, {3, 3}, {4, 4}});
  cv::Mat descriptors(4, 32, CV_8UC1);
  for (int r = 0; r < 4; ++r) descriptors.row(r).setTo(10 * (r + 1));
  const std::vector<std::uint8_t> flags = {0, 1, 1, 0};
  EXPECT_EQ(remove_flagged_keypoints(flags, keypoints, descriptors), 2);
  ASSERT_EQ(keypoints.size(), 2u);
  ASSERT_EQ(descriptors.rows, 2);
  EXPECT_FLOAT_EQ(keypoints[0].pt.x, 1.0f);
  EXPECT_FLOAT_EQ(keypoints[1].pt.x, 4.0f);
  EXPECT_EQ(descriptors.at<std::uint8_t>(0, 0), 10);
  EXPECT_EQ(descriptors.at<std::uint8_t>(1, 31), 40);  // row 3 moved up, aligned with keypoint 4
}

}  // namespace
}  // namespace pspslam
