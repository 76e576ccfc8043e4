#pragma once

#include <array>
#include <opencv2/core.hpp>
#include <span>
#include <string>
#include <vector>

#include "pspslam/dynamic/dynamic_pipeline.h"

namespace pspslam {

// Keypoints per fate, indexed by KeypointFate.
using FateCounts = std::array<int, 4>;

// The classes of the segmentation behind an overlay (names by label id, and which are dynamic).
struct OverlayClasses {
  std::vector<std::string> names;
  std::vector<int> dynamic_ids;
};

// A picture of one frame for `pspslam run --save-overlays`: the segmentation overlay of `labels`
// (semantic/overlay.h: dynamic classes strong and outlined, static ones muted; the plain frame
// when `labels` is empty), every keypoint marked by its fate (kept: circle, dropped: cross) and
// one legend: the classes present, then the fates with their counts.
cv::Mat draw_keypoint_overlay(const cv::Mat& bgr, const cv::Mat& labels,
                              const OverlayClasses& classes,
                              std::span<const KeypointRecord> keypoints);

}  // namespace pspslam
