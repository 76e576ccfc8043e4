#pragma once

#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace pspslam {

// Per-pixel class ids (CV_8UC1) at the size of the segmented image.
using LabelMap = cv::Mat;

// Semantic segmentation back-end (paper III.A). Implementations need not be thread-safe:
// each thread owns its own Segmenter (SemanticThread owns exactly one).
class Segmenter {
 public:
  virtual ~Segmenter() = default;

  // Labels for a CV_8UC3 BGR image; the result has the image's size.
  virtual LabelMap segment(const cv::Mat& bgr) = 0;

  // Class names indexed by label id.
  virtual const std::vector<std::string>& class_names() const = 0;

  // Ids of the classes treated as dynamic (potentially moving) by default.
  virtual std::vector<int> default_dynamic_classes() const = 0;
};

// 255 where the label is one of `dynamic_ids`, 0 elsewhere (CV_8UC1, size of `labels`);
// grown by `dilation_px` pixels (elliptic structuring element) when > 0, so that features on
// the silhouette of a person are also rejected.
cv::Mat dynamic_mask(const LabelMap& labels, const std::vector<int>& dynamic_ids,
                     int dilation_px = 0);

// Ids of `names` in `class_names`; throws pspslam::Error naming `context` and the unknown name.
std::vector<int> class_ids(const std::vector<std::string>& class_names,
                           const std::vector<std::string>& names, const std::string& context);

// PASCAL VOC colour map (BGR) for label `id`. Pictures for people use overlay_segmentation
// (semantic/overlay.h): dynamic classes strong and outlined, static ones muted, with a legend.
cv::Vec3b label_color(int id);

}  // namespace pspslam
