#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "pspslam/dynamic/mask_propagator.h"

namespace pspslam {
namespace {

constexpr int kWidth = 320;
constexpr int kHeight = 240;
const cv::Rect kPerson(100, 80, 60, 90);  // where the person is in frame 0

// Blurred noise: corners everywhere, and Lucas-Kanade has texture to lock on to.
cv::Mat texture(int seed) {
  cv::Mat noise(kHeight + 200, kWidth + 200, CV_8UC1);
  cv::RNG rng(static_cast<std::uint64_t>(seed));
  rng.fill(noise, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(noise, noise, cv::Size(5, 5), 1.5);
  return noise;
}

// A static, textured room with a person (its own texture) that has walked `shift` pixels.
cv::Mat frame_with_person(cv::Point shift) {
  static const cv::Mat room = texture(1);
  static const cv::Mat person = texture(2);
  cv::Mat image = room(cv::Rect(0, 0, kWidth, kHeight)).clone();
  person(cv::Rect(0, 0, kPerson.width, kPerson.height)).copyTo(image(kPerson + shift));
  return image;
}

cv::Mat person_mask() {
  cv::Mat mask = cv::Mat::zeros(kHeight, kWidth, CV_8UC1);
  mask(kPerson).setTo(255);
  return mask;
}

// A still camera: every frame-to-frame homography is the identity.
HomographyChain still_camera(int frames) {
  HomographyChain chain;
  chain.record(0, std::nullopt);
  for (int id = 1; id < frames; ++id) chain.record(id, Eigen::Matrix3d::Identity());
  return chain;
}

MaskPropagationParams no_growth() {
  MaskPropagationParams params;
  params.residual_speed_mps = 0.0;
  return params;
}

cv::Rect bounding_box(const cv::Mat& mask) { return cv::boundingRect(mask); }

TEST(MaskPropagator, AMaskOfTheCurrentFrameIsUsedAsItIs) {
  MaskPropagator propagator(500.0, 1.0 / 30.0);
  const cv::Mat depth(kHeight, kWidth, CV_32FC1, cv::Scalar(2.0f));
  propagator.add_frame(0, frame_with_person({0, 0}), depth);
  const PropagatedMask out = propagator.propagate(person_mask(), 0, 0, still_camera(1), true);
  EXPECT_EQ(out.age_frames, 0);
  EXPECT_EQ(cv::countNonZero(out.mask != person_mask()), 0);
  EXPECT_TRUE(out.watch.empty());
}

TEST(MaskPropagator, APersonWalkingBeforeAStillCameraIsFollowedByItsOwnFlow) {
  MaskPropagator propagator(500.0, 1.0 / 30.0, no_growth());
  const cv::Mat depth(kHeight, kWidth, CV_32FC1, cv::Scalar(2.0f));
  const HomographyChain chain = still_camera(6);
  for (int id = 0; id < 6; ++id) {
    propagator.add_frame(id, frame_with_person({5 * id, 2 * id}), depth);
    const PropagatedMask out = propagator.propagate(person_mask(), 0, id, chain, false);
    const cv::Rect box = bounding_box(out.mask);
    // Within a pixel of where the person really is; the homography alone would not move it.
    EXPECT_NEAR(box.x, kPerson.x + 5 * id, 1) << "frame " << id;
    EXPECT_NEAR(box.y, kPerson.y + 2 * id, 1) << "frame " << id;
    EXPECT_EQ(box.width, kPerson.width);
    EXPECT_EQ(box.height, kPerson.height);
    if (id > 0) {
      EXPECT_EQ(out.components, 1);
      EXPECT_EQ(out.moved_by_flow, 1);
      EXPECT_EQ(out.growth_px, 0);
    }
  }
}

TEST(MaskPropagator, AStaleMaskGrowsByHowFarAPersonWalksInItsAge) {
  MaskPropagationParams params;
  params.residual_speed_mps = 0.5;
  params.max_growth_px = 40;
  params.watch_band_px = 10;
  MaskPropagator propagator(500.0, 1.0 / 30.0, params);
  const cv::Mat depth(kHeight, kWidth, CV_32FC1, cv::Scalar(2.0f));
  for (int id = 0; id <= 4; ++id) propagator.add_frame(id, frame_with_person({0, 0}), depth);
  const PropagatedMask out = propagator.propagate(person_mask(), 0, 4, still_camera(5), true);
  // 0.5 m/s for 4 frames at 30 Hz, 2 m away, f = 500 px: 16.7 px, rounded up.
  EXPECT_EQ(out.growth_px, 17);
  const int row = kPerson.y + kPerson.height / 2;
  const int right = kPerson.x + kPerson.width - 1;
  EXPECT_EQ(out.mask.at<std::uint8_t>(row, right + 17), 255);
  EXPECT_EQ(out.mask.at<std::uint8_t>(row, right + 19), 0);
  EXPECT_EQ(out.watch.at<std::uint8_t>(row, right + 27), 255);
  EXPECT_EQ(out.watch.at<std::uint8_t>(row, right + 29), 0);
  // The moved mask before growing (for culling map points) is the person's own outline.
  EXPECT_EQ(cv::countNonZero(out.moved != person_mask()), 0);
}

TEST(MaskPropagator, GrowsFartherForAPersonNearerTheCameraAndNoFartherThanTheCap) {
  MaskPropagationParams params;
  params.max_growth_px = 30;
  MaskPropagator propagator(500.0, 1.0 / 30.0, params);
  const cv::Mat near(kHeight, kWidth, CV_32FC1, cv::Scalar(0.5f));
  for (int id = 0; id <= 4; ++id) propagator.add_frame(id, frame_with_person({0, 0}), near);
  EXPECT_EQ(propagator.propagate(person_mask(), 0, 4, still_camera(5), false).growth_px, 30);
}

TEST(MaskPropagator, APartWithoutTextureMovesWithTheCameraHomography) {
  MaskPropagator propagator(500.0, 1.0 / 30.0, no_growth());
  const cv::Mat flat(kHeight, kWidth, CV_8UC1, cv::Scalar(128));
  const cv::Mat depth(kHeight, kWidth, CV_32FC1, cv::Scalar(2.0f));
  HomographyChain chain;
  chain.record(0, std::nullopt);
  Eigen::Matrix3d H = Eigen::Matrix3d::Identity();
  H(0, 2) = 7.0;  // the camera pans: everything moves 7 px right per frame
  for (int id = 0; id <= 2; ++id) {
    if (id > 0) chain.record(id, H);
    propagator.add_frame(id, flat, depth);
  }
  const PropagatedMask out = propagator.propagate(person_mask(), 0, 2, chain, false);
  EXPECT_EQ(out.moved_by_flow, 0);
  EXPECT_EQ(bounding_box(out.mask).x, kPerson.x + 14);
}

}  // namespace
}  // namespace pspslam
