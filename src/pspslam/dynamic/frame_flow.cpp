#include "pspslam/dynamic/frame_flow.h"

#include <opencv2/video/tracking.hpp>

namespace pspslam {

void FrameFlow::track(const cv::Mat& previous_gray, const cv::Mat& current_gray,
                      const std::vector<cv::Point2f>& previous_points) {
  matched_previous_.clear();
  matched_current_.clear();
  if (previous_gray.empty() || current_gray.empty() || previous_points.empty()) return;
  from_.clear();
  const size_t n = previous_points.size();
  const size_t step = n > static_cast<size_t>(max_points_) ? n / max_points_ : 1;
  for (size_t i = 0; i < n && from_.size() < static_cast<size_t>(max_points_); i += step)
    from_.push_back(previous_points[i]);
  cv::calcOpticalFlowPyrLK(previous_gray, current_gray, from_, to_, status_, error_,
                           cv::Size(21, 21), 3);
  for (size_t i = 0; i < from_.size(); ++i) {
    if (!status_[i]) continue;
    matched_previous_.emplace_back(from_[i].x, from_[i].y);
    matched_current_.emplace_back(to_[i].x, to_[i].y);
  }
}

}  // namespace pspslam
