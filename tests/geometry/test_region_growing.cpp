#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "pspslam/geometry/region_growing.h"

namespace pspslam {
namespace {

constexpr float kFocalPx = 525.0f;

// A wall at 3 m with an upright box (a person's size in the image) 1.5 m away in front of it. Boxes
// below are aligned to the 4-pixel growth grid: an edge inside a block whose sample lies on the
// other side is the grid's known limit, not what these tests are about.
cv::Mat wall_with_box(cv::Rect box) {
  cv::Mat depth(480, 640, CV_32FC1, cv::Scalar(3.0f));
  depth(box).setTo(1.5f);
  return depth;
}

int masked_inside(const cv::Mat& mask, cv::Rect box) { return cv::countNonZero(mask(box)); }

TEST(RegionGrowing, FillsTheSeededSurfaceAndStopsAtItsDepthStep) {
  const cv::Rect box(260, 148, 80, 204);
  const cv::Mat depth = wall_with_box(box);
  const std::vector<Eigen::Vector2f> seeds = {{300.0f, 200.0f}, {290.0f, 300.0f}};
  const std::vector<float> seed_depths = {1.5f, 1.5f};
  DynamicRegionGrower grower(RegionGrowParams{}, kFocalPx);
  cv::Mat mask;
  grower.grow(depth, seeds, seed_depths, {}, mask);
  // Pixel-exact: the whole box, nothing of the wall (the metric radius, 0.5 m at 1.5 m = 175 px,
  // reaches every corner of the box from either seed).
  EXPECT_EQ(masked_inside(mask, box), box.area());
  EXPECT_EQ(cv::countNonZero(mask), box.area());
}

TEST(RegionGrowing, ARegionOneSeedSupportsIsDropped) {
  const cv::Rect box(260, 148, 80, 204);
  const cv::Mat depth = wall_with_box(box);
  const std::vector<Eigen::Vector2f> seeds = {{300.0f, 200.0f}};
  const std::vector<float> seed_depths = {1.5f};
  DynamicRegionGrower grower(RegionGrowParams{}, kFocalPx);
  cv::Mat mask;
  grower.grow(depth, seeds, seed_depths, {}, mask);
  EXPECT_EQ(cv::countNonZero(mask), 0);
}

// The grower keeps buffers between calls and clears only what the last call claimed: a reused
// grower must give exactly what a fresh one gives, also after a call that grew a larger region over
// the same cells (without the clear, this test fails).
TEST(RegionGrowing, ReusedGrowerMatchesAFreshOne) {
  const cv::Rect large(100, 40, 300, 400), small(300, 200, 60, 152);
  const cv::Mat first = wall_with_box(large), second = wall_with_box(small);
  const std::vector<Eigen::Vector2f> first_seeds = {{200.0f, 200.0f}, {260.0f, 260.0f}};
  const std::vector<Eigen::Vector2f> second_seeds = {
      {320.0f, 250.0f}, {330.0f, 300.0f}, {200.0f, 200.0f}};  // the last one lies on the wall
  const std::vector<float> first_depths = {1.5f, 1.5f}, second_depths = {1.5f, 1.5f, 3.0f};
  DynamicRegionGrower reused(RegionGrowParams{}, kFocalPx);
  cv::Mat mask;
  reused.grow(first, first_seeds, first_depths, {}, mask);
  EXPECT_GT(masked_inside(mask, large), large.area() / 2);
  reused.grow(second, second_seeds, second_depths, {}, mask);
  DynamicRegionGrower fresh(RegionGrowParams{}, kFocalPx);
  cv::Mat expected;
  fresh.grow(second, second_seeds, second_depths, {}, expected);
  EXPECT_EQ(cv::countNonZero(mask != expected), 0);
  EXPECT_EQ(masked_inside(expected, small), small.area());
  // The lone wall seed's region has one seed: dropped, so only the box is masked.
  EXPECT_EQ(cv::countNonZero(expected), small.area());
}

}  // namespace
}  // namespace pspslam
