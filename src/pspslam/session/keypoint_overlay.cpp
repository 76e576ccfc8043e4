#include "pspslam/session/keypoint_overlay.h"

#include <opencv2/imgproc.hpp>
#include <string>

#include "pspslam/semantic/segmenter.h"

namespace pspslam {
namespace {

struct FateStyle {
  cv::Scalar color;  // BGR
  int marker;        // cv::MarkerTypes
  const char* label;
};

// Kept keypoints are circles, dropped ones crosses, so the picture reads without colour too.
// Red and cyan stay visible on the VOC person colour (pink) of the semantic overlay.
FateStyle style(KeypointFate fate) {
  switch (fate) {
    case KeypointFate::tracked:
      return {cv::Scalar(0, 210, 0), -1, "tracked (map point match)"};
    case KeypointFate::unmatched:
      return {cv::Scalar(0, 215, 255), -1, "kept, unmatched or outlier"};
    case KeypointFate::semantic:
      return {cv::Scalar(0, 0, 255), cv::MARKER_TILTED_CROSS, "dropped: semantic mask"};
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

void draw_fate_legend(cv::Mat& image, const FateCounts& counts) {
  constexpr int kLine = 18;
  const cv::Rect box(6, 6, 250, 10 + kLine * static_cast<int>(counts.size()));
  cv::Mat area = image(box & cv::Rect(0, 0, image.cols, image.rows));
  area.convertTo(area, -1, 0.35);  // darkened, so the text reads on any frame
  for (size_t i = 0; i < counts.size(); ++i) {
    const FateStyle s = style(static_cast<KeypointFate>(i));
    const int y = box.y + 14 + kLine * static_cast<int>(i);
    draw_marker(image, cv::Point2f(static_cast<float>(box.x + 12), static_cast<float>(y - 4)), s);
    cv::putText(image, std::string(s.label) + " " + std::to_string(counts[i]),
                cv::Point(box.x + 24, y), cv::FONT_HERSHEY_SIMPLEX, 0.42, cv::Scalar(255, 255, 255),
                1, cv::LINE_AA);
  }
}

cv::Mat draw_keypoint_overlay(const cv::Mat& bgr, const cv::Mat& labels,
                              std::span<const KeypointRecord> keypoints) {
  cv::Mat image = labels.empty() ? bgr.clone() : overlay_labels(bgr, labels);
  FateCounts counts{};
  for (const KeypointRecord& keypoint : keypoints) {
    draw_marker(image, keypoint.position, style(keypoint.fate));
    ++counts[static_cast<size_t>(keypoint.fate)];
  }
  draw_fate_legend(image, counts);
  return image;
}

}  // namespace pspslam
