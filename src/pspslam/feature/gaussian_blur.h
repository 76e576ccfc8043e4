#pragma once

#include <opencv2/core.hpp>

namespace pspslam {

// Half-width of the 7x7 smoothing kernel used before the BRIEF tests.
inline constexpr int kDescriptorBlurRadius = 3;

// 7x7 Gaussian (sigma 2, the ORB smoothing) of a CV_8UC1 image with 8-bit integer weights
// [18 33 49 56 49 33 18] / 256 per axis: within 1 grey level of cv::GaussianBlur and several
// times faster, because both passes stay in 16-bit lanes that the compiler vectorises.
//
// No border is extrapolated: only pixels at least kDescriptorBlurRadius from every edge of `dst`
// are written (the frame keeps whatever `dst` held). The extractor runs it on levels that carry
// a reflected border wider than that, so every pixel a descriptor reads is a real result.
// `vertical_pass` is scratch storage reused between calls; `dst` is (re)created at src's size.
void gaussian_blur_7x7(const cv::Mat& src, cv::Mat& vertical_pass, cv::Mat& dst);

}  // namespace pspslam
