#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "pspslam/dynamic/mask_warper.h"
#include "pspslam/semantic/semantic_thread.h"

namespace pspslam {
namespace {

Eigen::Matrix3d translation(double dx, double dy) {
  Eigen::Matrix3d H = Eigen::Matrix3d::Identity();
  H(0, 2) = dx;
  H(1, 2) = dy;
  return H;
}

cv::Mat square_mask(int x, int y) {
  cv::Mat mask = cv::Mat::zeros(120, 160, CV_8UC1);
  mask(cv::Rect(x, y, 20, 20)).setTo(255);
  return mask;
}

TEST(HomographyChain, ChainsStepsAndRefusesGaps) {
  HomographyChain chain;
  chain.record(0, std::nullopt);  // first frame: no previous one
  chain.record(1, translation(5, 0));
  chain.record(2, translation(5, 1));
  chain.record(3, translation(-2, 0));
  const auto H = chain.between(0, 3);
  ASSERT_TRUE(H);
  EXPECT_NEAR((*H)(0, 2), 8.0, 1e-12);
  EXPECT_NEAR((*H)(1, 2), 1.0, 1e-12);
  EXPECT_TRUE(chain.between(2, 2)->isIdentity());
  chain.record(4, std::nullopt);  // homography failed here
  EXPECT_FALSE(chain.between(1, 4));
  EXPECT_FALSE(chain.between(3, 1));
}

TEST(MaskWarper, ASquareMovesWithTheKnownHomography) {
  HomographyChain chain;
  chain.record(10, std::nullopt);
  chain.record(11, translation(6, 0));
  chain.record(12, translation(6, 4));
  const WarpedMask warped = warp_mask_to_frame(square_mask(40, 30), 10, 12, chain);
  ASSERT_FALSE(warped.mask.empty());
  EXPECT_TRUE(warped.warped);
  EXPECT_EQ(warped.age_frames, 2);
  EXPECT_EQ(cv::countNonZero(warped.mask != square_mask(52, 34)), 0);
  // Label maps stay binary: nearest neighbour invents no values.
  EXPECT_EQ(cv::countNonZero(warped.mask == 255) + cv::countNonZero(warped.mask == 0),
            warped.mask.rows * warped.mask.cols);
  // The frame's own mask is used as it is.
  const cv::Mat own = square_mask(1, 1);
  EXPECT_EQ(warp_mask_to_frame(own, 12, 12, chain).mask.data, own.data);
}

TEST(MaskWarper, ABrokenChainDropsTheMaskRatherThanMisplaceIt) {
  HomographyChain chain;
  chain.record(0, std::nullopt);
  chain.record(1, std::nullopt);
  const WarpedMask warped = warp_mask_to_frame(square_mask(40, 30), 0, 1, chain);
  EXPECT_TRUE(warped.mask.empty());
}

// Segments every frame as a 20x20 "person" square at x = 10 * frame id.
class SquareSegmenter : public Segmenter {
 public:
  LabelMap segment(const cv::Mat& bgr) override {
    cv::Mat labels = cv::Mat::zeros(bgr.size(), CV_8UC1);
    labels(cv::Rect(10 * bgr.at<cv::Vec3b>(0, 0)[0], 30, 20, 20)).setTo(15);
    return labels;
  }
  const std::vector<std::string>& class_names() const override { return names_; }
  std::vector<int> default_dynamic_classes() const override { return {15}; }

 private:
  std::vector<std::string> names_ = std::vector<std::string>(16, "x");
};

// The real-time policy: take the newest published mask and warp it through the homographies of
// the frames since.
TEST(MaskWarper, NewestSemanticMaskIsWarpedIntoTheCurrentFrame) {
  SemanticParams params;
  params.mask_dilation_px = 0;
  params.queue_size = 4;
  SemanticThread thread(std::make_unique<SquareSegmenter>(), params);
  for (int id = 0; id < 3; ++id) {
    cv::Mat bgr = cv::Mat::zeros(120, 160, CV_8UC3);
    bgr.at<cv::Vec3b>(0, 0)[0] = static_cast<unsigned char>(id);  // tells the fake its frame
    thread.submit(id, 0.1 * id, bgr);
  }
  thread.wait_idle();
  const auto newest = thread.newest();
  ASSERT_TRUE(newest);
  EXPECT_EQ(newest->frame_id, 2);

  HomographyChain chain;
  chain.record(2, std::nullopt);
  chain.record(3, translation(0, 5));
  chain.record(4, translation(3, 5));
  const WarpedMask warped = warp_mask_to_frame(newest->dynamic_mask, newest->frame_id, 4, chain);
  ASSERT_FALSE(warped.mask.empty());
  EXPECT_EQ(warped.age_frames, 2);
  EXPECT_EQ(cv::countNonZero(warped.mask != square_mask(23, 40)), 0);
}

}  // namespace
}  // namespace pspslam
