#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>
#include <vector>

#include "pspslam/feature/orb_extractor.h"
#include "pspslam/match/stereo_matcher.h"
#include "pspslam/synth/scene.h"

namespace pspslam {
namespace {

double median(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + static_cast<long>(values.size() / 2),
                   values.end());
  return values[values.size() / 2];
}

// Smooth random texture: blurred noise, so a sub-pixel shift is well defined.
cv::Mat texture(int rows, int cols, unsigned seed) {
  cv::Mat noise(rows, cols, CV_32F);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uniform(0.0f, 255.0f);
  for (int y = 0; y < rows; ++y)
    for (int x = 0; x < cols; ++x) noise.at<float>(y, x) = uniform(rng);
  cv::GaussianBlur(noise, noise, cv::Size(0, 0), 1.5);
  cv::normalize(noise, noise, 0, 255, cv::NORM_MINMAX);
  cv::Mat image;
  noise.convertTo(image, CV_8U);
  return image;
}

struct Pair {
  std::vector<cv::KeyPoint> left_keypoints, right_keypoints;
  cv::Mat left_descriptors, right_descriptors;
};

Pair extract(const cv::Mat& left, const cv::Mat& right, const OrbConfig& orb) {
  OrbExtractor extractor(orb);
  OrbFeatures features;
  Pair pair;
  extractor.extract(left, cv::Mat(), features);
  pair.left_keypoints = features.keypoints;
  pair.left_descriptors = features.descriptors.clone();
  OrbConfig right_orb = orb;  // as system/frame_builder.cpp extracts the right image
  right_orb.n_features *= 2;
  OrbExtractor right_extractor(right_orb);
  right_extractor.extract(right, cv::Mat(), features);
  pair.right_keypoints = features.keypoints;
  pair.right_descriptors = features.descriptors.clone();
  return pair;
}

// A fronto-parallel textured plane: the right image is the left shifted by a known fractional
// disparity, so every match has the same true disparity.
TEST(StereoMatcher, FindsAKnownSubPixelDisparity) {
  const OrbConfig orb;
  const ScalePyramid pyramid = ScalePyramid::from_config(orb);
  const cv::Mat left = texture(480, 640, 7);
  for (const double true_disparity : {12.3, 20.5, 31.75}) {
    cv::Mat right;
    const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, -true_disparity, 0, 1, 0);
    cv::warpAffine(left, right, shift, left.size(), cv::INTER_CUBIC, cv::BORDER_REFLECT);
    const Pair pair = extract(left, right, orb);
    const double bf = 525.0 * 0.1;
    StereoDepths depths;
    match_stereo(pair.left_keypoints, pair.left_descriptors, pair.right_keypoints,
                 pair.right_descriptors, left, right, pyramid, bf, StereoMatchOptions{}, depths);
    std::vector<double> errors;
    for (size_t i = 0; i < pair.left_keypoints.size(); ++i) {
      if (depths.depth[i] <= 0.0f) continue;
      const double disparity = pair.left_keypoints[i].pt.x - depths.right_u[i];
      EXPECT_NEAR(bf / disparity, depths.depth[i], 1e-3 * depths.depth[i]);
      errors.push_back(std::abs(disparity - true_disparity));
    }
    SCOPED_TRACE(true_disparity);
    // Most keypoints away from the left border (where the right image has no partner) match.
    EXPECT_GT(errors.size(), pair.left_keypoints.size() * 6 / 10);
    EXPECT_LT(median(errors), 0.1);
    std::sort(errors.begin(), errors.end());
    EXPECT_LT(errors[errors.size() * 95 / 100], 0.25);
  }
}

// The stereo matcher's accuracy on a rendered pair: the synthetic room's right camera (synth/)
// against the exact depth of the left one.
TEST(StereoMatcher, RenderedPairDisparityWithinAQuarterPixel) {
  SynthOptions options;
  options.frames = 1;
  options.bodies = 0;
  options.depth_noise = false;
  options.stereo_baseline = 0.1;
  options.threads = 1;
  const SyntheticScene scene(options);
  const SynthFrame frame = scene.render(0);
  cv::Mat right_bgr, left, right;
  scene.render_right(0, right_bgr, 1);
  cv::cvtColor(frame.bgr, left, cv::COLOR_BGR2GRAY);
  cv::cvtColor(right_bgr, right, cv::COLOR_BGR2GRAY);
  const OrbConfig orb;
  const ScalePyramid pyramid = ScalePyramid::from_config(orb);
  const Pair pair = extract(left, right, orb);
  const double bf = scene.camera().fx * options.stereo_baseline;
  StereoDepths depths;
  match_stereo(pair.left_keypoints, pair.left_descriptors, pair.right_keypoints,
               pair.right_descriptors, left, right, pyramid, bf, StereoMatchOptions{}, depths);
  std::vector<double> errors;
  for (size_t i = 0; i < pair.left_keypoints.size(); ++i) {
    if (depths.depth[i] <= 0.0f) continue;
    const cv::Point2f p = pair.left_keypoints[i].pt;
    const float z = frame.depth.at<float>(cvRound(p.y), cvRound(p.x));
    errors.push_back(std::abs((p.x - depths.right_u[i]) - bf / z));
  }
  EXPECT_GT(depths.matched, static_cast<int>(pair.left_keypoints.size()) * 6 / 10);
  EXPECT_LT(median(errors), 0.25);
  std::sort(errors.begin(), errors.end());
  RecordProperty("median_error_px", std::to_string(median(errors)));
  std::printf(
      "rendered pair: %d of %zu matched, disparity error median %.3f px, p90 %.3f px, max %.3f "
      "px\n",
      depths.matched, pair.left_keypoints.size(), errors[errors.size() / 2],
      errors[errors.size() * 9 / 10], errors.back());
}

}  // namespace
}  // namespace pspslam
