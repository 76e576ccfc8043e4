#pragma once

#include <opencv2/core.hpp>

#include <string>
#include <vector>

#include "pspslam/semantic/segmenter.h"

namespace pspslam {

// One row of a legend drawn into an image: a colour swatch and its text.
struct LegendEntry {
  std::string label;
  cv::Vec3b colour;  // BGR
};

// Draws `entries` as a legend box (semi-opaque dark background, swatch + white text per row,
// cv::putText) whose top-left corner is `corner`, clipped to the image. Returns the box drawn
// (empty when there is no entry). `image` must be CV_8UC3. Reusable for any per-frame picture
// (segmentation overlays, keypoint fates).
cv::Rect draw_legend(cv::Mat& image, const std::vector<LegendEntry>& entries,
                     cv::Point corner = {8, 8});

struct OverlayStyle {
  // Dynamic classes are what the system masks, so they must catch the eye: strong colour at a
  // high blend and an outline; static classes are context only: desaturated, low blend.
  double dynamic_alpha = 0.6;
  double static_alpha = 0.3;
  double static_saturation = 0.35;  // share of the class colour's chroma kept for static classes
  int outline_px = 2;               // contour thickness around each dynamic region (0 = none)
  bool legend = true;
};

// Colour of class `id` in an overlay: a saturated colour for dynamic classes (the person class
// always red; other dynamic classes take the colours of a fixed vivid palette by their rank in
// `dynamic_ids`, so a colour never changes between frames of one run) and the PASCAL VOC
// colour pulled towards grey for static classes.
cv::Vec3b overlay_class_colour(int id, const std::vector<int>& dynamic_ids,
                               const std::vector<std::string>& class_names,
                               const OverlayStyle& style = {});

// Legend rows for the classes present in `labels` (background id 0 left out): dynamic classes
// first, each as "<name> (dynamic)", then static ones, both by decreasing pixel count.
std::vector<LegendEntry> overlay_legend_entries(const LabelMap& labels,
                                                const std::vector<int>& dynamic_ids,
                                                const std::vector<std::string>& class_names,
                                                const OverlayStyle& style = {});

// The segmentation overlay people read: `labels` (CV_8UC1) blended on `bgr` (CV_8UC3, same size)
// with strong colours + outlines for `dynamic_ids` and muted colours for the other classes,
// plus the legend in the top-left corner. Class names index by label id (ids without a name
// are shown as "class <id>"). Throws pspslam::Error on mismatched types or sizes.
cv::Mat overlay_segmentation(const cv::Mat& bgr, const LabelMap& labels,
                             const std::vector<int>& dynamic_ids,
                             const std::vector<std::string>& class_names,
                             const OverlayStyle& style = {});

}  // namespace pspslam
