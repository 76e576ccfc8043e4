#pragma once

#include <array>
#include <opencv2/core.hpp>
#include <span>

#include "pspslam/dynamic/dynamic_pipeline.h"

namespace pspslam {

// Keypoints per fate, indexed by KeypointFate.
using FateCounts = std::array<int, 4>;

// A picture of one frame for `pspslam run --save-overlays`: the semantic overlay of `labels`
// (semantic/ overlay_labels; the plain frame when `labels` is empty), every keypoint marked by
// its fate (kept: circle, dropped: cross) and a legend with the counts.
cv::Mat draw_keypoint_overlay(const cv::Mat& bgr, const cv::Mat& labels,
                              std::span<const KeypointRecord> keypoints);

// The legend, top left. Kept in one function so that a shared legend helper can replace it.
void draw_fate_legend(cv::Mat& image, const FateCounts& counts);

}  // namespace pspslam
