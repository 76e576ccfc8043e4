#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

namespace pspslam {

// Sparse correspondences previous -> current frame for the compensated homography (eq. 10-11):
// pyramidal Lucas-Kanade on up to `max_points` of the previous frame's static keypoints. Much
// cheaper than descriptor matching and independent of tracking, so the homography exists even
// when tracking is lost. Buffers are reused between frames.
class FrameFlow {
 public:
  explicit FrameFlow(int max_points = 200) : max_points_(max_points) {}

  // `previous_points`: candidates in the previous image (subsampled evenly to max_points).
  // Fills matched_previous / matched_current with the successfully tracked pairs.
  void track(const cv::Mat& previous_gray, const cv::Mat& current_gray,
             const std::vector<cv::Point2f>& previous_points);

  const std::vector<Eigen::Vector2d>& matched_previous() const { return matched_previous_; }
  const std::vector<Eigen::Vector2d>& matched_current() const { return matched_current_; }

 private:
  int max_points_;
  std::vector<cv::Point2f> from_;
  std::vector<cv::Point2f> to_;
  std::vector<unsigned char> status_;
  std::vector<float> error_;
  std::vector<Eigen::Vector2d> matched_previous_;
  std::vector<Eigen::Vector2d> matched_current_;
};

}  // namespace pspslam
