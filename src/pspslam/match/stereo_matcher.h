#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "pspslam/map/scale_pyramid.h"

namespace pspslam {

// Matching of one rectified stereo pair's ORB keypoints.
struct StereoMatchOptions {
  // Nearest depth looked for: sets the widest disparity searched, bf / min_depth_m.
  double min_depth_m = 0.3;
  // Hamming distance a descriptor match must beat (ORB-SLAM2's mean of its high and low
  // thresholds: looser than frame-to-frame matching because the row constraint is strong).
  int max_descriptor_distance = 75;
  // Half-size of the SAD window on the full-resolution images (11 x 11 pixels).
  int sad_half_window = 5;
  // The SAD search runs over +-sad_search_px * scale of the keypoint's level around the
  // descriptor match: a keypoint found on level l is only known to ~scale(l) pixels.
  int sad_search_px = 3;
  // A match whose best SAD per pixel exceeds this factor times the median over the pair is
  // rejected (a repeated texture or an occlusion that fooled the descriptor).
  double max_sad_to_median = 2.1;
};

// Per left keypoint: depth in metres (-1: no stereo match) and the measured right coordinate
// (NaN without a match), the layout Frame uses for RGB-D's virtual right coordinate.
struct StereoDepths {
  std::vector<float> depth;
  std::vector<float> right_u;
  int matched = 0;
};

// Finds each left keypoint's partner along its row band in the right image (the band is
// +-2 scale(level) rows: keypoints on coarse levels are known to several pixels), among right
// keypoints within one pyramid level and with disparity in [0, bf / min_depth_m], by the
// smallest Hamming distance; then refines the disparity to a fraction of a pixel by the sum of
// absolute differences of zero-mean 11x11 patches over a few pixels and a parabola through the
// best three SAD values. `left_gray`, `right_gray`: the rectified full-resolution images (CV_8UC1)
// the keypoints were extracted from; keypoints in their (rectified, undistorted) coordinates.
// `out` is overwritten, its buffers reused.
void match_stereo(const std::vector<cv::KeyPoint>& left, const cv::Mat& left_descriptors,
                  const std::vector<cv::KeyPoint>& right, const cv::Mat& right_descriptors,
                  const cv::Mat& left_gray, const cv::Mat& right_gray, const ScalePyramid& pyramid,
                  double bf, const StereoMatchOptions& options, StereoDepths& out);

}  // namespace pspslam
