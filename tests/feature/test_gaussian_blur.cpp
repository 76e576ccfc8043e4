#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "feature_test_images.h"
#include "pspslam/feature/gaussian_blur.h"

namespace pspslam {
namespace {

TEST(GaussianBlur7x7, WithinOneGreyLevelOfOpenCvInside) {
  const cv::Mat image = testing::make_textured_image(200, 150, 21);
  cv::Mat scratch;
  cv::Mat ours(image.size(), CV_8UC1, cv::Scalar(77));
  gaussian_blur_7x7(image, scratch, ours);
  cv::Mat reference;
  cv::GaussianBlur(image, reference, cv::Size(7, 7), 2.0, 2.0, cv::BORDER_REFLECT_101);
  const cv::Rect inside(kDescriptorBlurRadius, kDescriptorBlurRadius,
                        image.cols - 2 * kDescriptorBlurRadius,
                        image.rows - 2 * kDescriptorBlurRadius);
  EXPECT_LE(cv::norm(ours(inside), reference(inside), cv::NORM_INF), 1.0);
  // The frame is not written.
  EXPECT_EQ(ours.at<std::uint8_t>(0, 0), 77);
  EXPECT_EQ(ours.at<std::uint8_t>(image.rows - 1, 100), 77);
  // A constant image stays constant (weights sum to exactly 256).
  const cv::Mat flat(40, 40, CV_8UC1, cv::Scalar(255));
  cv::Mat flat_blurred;
  gaussian_blur_7x7(flat, scratch, flat_blurred);
  EXPECT_EQ(cv::norm(flat_blurred(cv::Rect(3, 3, 34, 34)), cv::NORM_INF), 255.0);
  EXPECT_EQ(cv::countNonZero(flat_blurred(cv::Rect(3, 3, 34, 34)) != 255), 0);
}

}  // namespace
}  // namespace pspslam
