#include "pspslam/session/keypoint_overlay.h"

#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "pspslam/semantic/overlay.h"

namespace pspslam {
namespace {

struct FateStyle {
  cv::Scalar color;  // BGR
  int marker;        // cv::MarkerTypes
  const char* label;
};

// Kept keypoints are circles, dropped ones crosses, so the picture reads without colour too.
// Dropped-by-mask crosses are blue-violet, not red: the person class is drawn red.
FateStyle style_of(KeypointFate fate) {
  switch (fate) {
    case KeypointFate::tracked:
      return {cv::Scalar(0, 210, 0), -1, "tracked (map point match)"};
    case KeypointFate::unmatched:
      return {cv::Scalar(0, 215, 255), -1, "kept, unmatched or outlier"};
    case KeypointFate::semantic:
      return {cv::Scalar(255, 60, 160), cv::MARKER_TILTED_CROSS, "dropped: semantic mask"};
    case KeypointFate::geometry:
      return {cv::Scalar(255, 255, 0), cv::MARKER_TILTED_CROSS, "dropped: geometry test"};
  }
  return {cv::Scalar(255, 255, 255), -1, "?"};
}

void draw_marker(cv::Mat& image, const cv::Point2f& position, const FateStyle& s) {
  if (s.marker < 0) {
    cv::circle(image, position, 3, s.color, 1, cv::LINE_AA);
  } else {
    cv::drawMarker(image, position, s.color, s.marker, 7, 2, cv::LINE_AA);
  }
}

}  // namespace

cv::Mat draw_keypoint_overlay(const cv::Mat& bgr, const cv::Mat& labels,
                              const OverlayClasses& classes,
                              std::span<const KeypointRecord> keypoints) {
  OverlayStyle style;
  style.legend = false;  // one legend below: classes and fates together
  cv::Mat image =
      labels.empty() ? bgr.clone()
                     : overlay_segmentation(bgr, labels, classes.dynamic_ids, classes.names, style);
  FateCounts counts{};
  for (const KeypointRecord& keypoint : keypoints) {
    draw_marker(image, keypoint.position, style_of(keypoint.fate));
    ++counts[static_cast<size_t>(keypoint.fate)];
  }
  std::vector<LegendEntry> legend =
      labels.empty() ? std::vector<LegendEntry>{}
                     : overlay_legend_entries(labels, classes.dynamic_ids, classes.names, style);
  for (size_t i = 0; i < counts.size(); ++i) {
    const FateStyle fate = style_of(static_cast<KeypointFate>(i));
    const cv::Scalar& c = fate.color;
    legend.push_back(
        {std::string(fate.label) + " " + std::to_string(counts[i]),
         cv::Vec3b(static_cast<uchar>(c[0]), static_cast<uchar>(c[1]), static_cast<uchar>(c[2]))});
  }
  draw_legend(image, legend);
  return image;
}

}  // namespace pspslam
