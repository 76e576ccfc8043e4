#include "pspslam/dynamic/keypoint_fusion.h"

#include <opencv2/imgproc.hpp>

#include "pspslam/core/error.h"

namespace pspslam {

int fuse_keypoint_flags(std::span<const cv::KeyPoint> keypoints, const cv::Mat& semantic_mask,
                        std::span<const std::uint8_t> geometry_dynamic,
                        std::vector<std::uint8_t>& dynamic) {
  if (!geometry_dynamic.empty() && geometry_dynamic.size() != keypoints.size()) {
    throw Error("fuse_keypoint_flags: " + std::to_string(geometry_dynamic.size()) +
                " geometry flags for " + std::to_string(keypoints.size()) + " keypoints");
  }
  if (!semantic_mask.empty() && semantic_mask.type() != CV_8UC1)
    throw Error("fuse_keypoint_flags: the semantic mask must be CV_8UC1");
  dynamic.assign(keypoints.size(), 0);
  int count = 0;
  for (size_t i = 0; i < keypoints.size(); ++i) {
    bool is_dynamic = !geometry_dynamic.empty() && geometry_dynamic[i] != 0;
    if (!is_dynamic && !semantic_mask.empty()) {
      const int u = cvRound(keypoints[i].pt.x);
      const int v = cvRound(keypoints[i].pt.y);
      is_dynamic = u >= 0 && v >= 0 && u < semantic_mask.cols && v < semantic_mask.rows &&
                   semantic_mask.at<std::uint8_t>(v, u) != 0;
    }
    dynamic[i] = is_dynamic ? 1 : 0;
    count += is_dynamic ? 1 : 0;
  }
  return count;
}

int remove_flagged_keypoints(std::span<const std::uint8_t> dynamic,
                             std::vector<cv::KeyPoint>& keypoints, cv::Mat& descriptors) {
  if (dynamic.size() != keypoints.size() || descriptors.rows != static_cast<int>(keypoints.size()))
    throw Error("remove_flagged_keypoints: flags, keypoints and descriptors differ in count");
  int kept = 0;
  for (size_t i = 0; i < keypoints.size(); ++i) {
    if (dynamic[i]) continue;
    if (kept != static_cast<int>(i)) {
      keypoints[kept] = keypoints[i];
      descriptors.row(static_cast<int>(i)).copyTo(descriptors.row(kept));
    }
    ++kept;
  }
  const int removed = static_cast<int>(keypoints.size()) - kept;
  keypoints.resize(kept);
  // A header over the first rows: the descriptor block is not copied again.
  descriptors = descriptors.rowRange(0, kept);
  return removed;
}

cv::Mat dilate_mask(const cv::Mat& mask, int margin_px) {
  if (mask.empty() || margin_px <= 0) return mask;
  cv::Mat grown;
  const int k = 2 * margin_px + 1;
  cv::dilate(mask, grown, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(k, k)));
  return grown;
}

}  // namespace pspslam
