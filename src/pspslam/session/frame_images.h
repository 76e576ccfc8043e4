#pragma once

#include <filesystem>
#include <opencv2/core.hpp>
#include <span>
#include <string>

#include "pspslam/dynamic/dynamic_pipeline.h"
#include "pspslam/session/keypoint_overlay.h"

namespace pspslam {

// Per-frame pictures of a run, as DynaSLAM writes them (`pspslam run --save-masks DIR`,
// `--save-overlays DIR`): one PNG per processed frame, named after the frame's colour image
// (rgb/1548339828.32144.png -> DIR/1548339828.32144.png). The folders are prepared beforehand
// (prepare_run_outputs); an empty folder writes nothing.
class FrameImageWriter {
 public:
  FrameImageWriter(std::filesystem::path masks, std::filesystem::path overlays)
      : masks_(std::move(masks)), overlays_(std::move(overlays)) {}

  // The segmentation's class names and dynamic classes, for the overlays' colours and legend.
  void set_classes(OverlayClasses classes) { classes_ = std::move(classes); }

  bool writes_masks() const { return !masks_.empty(); }
  bool writes_overlays() const { return !overlays_.empty(); }

  // The final (fused semantic + geometry) dynamic mask as 8-bit 0/255 of `size`; an empty mask
  // (no dynamic detection, or none yet) is written all 0. Throws pspslam::Error naming the file.
  void write_mask(const std::filesystem::path& rgb_file, const cv::Mat& dynamic_mask,
                  cv::Size size);
  // The keypoint overlay (keypoint_overlay.h). Throws pspslam::Error naming the file.
  void write_overlay(const std::filesystem::path& rgb_file, const cv::Mat& bgr,
                     const cv::Mat& labels, std::span<const KeypointRecord> keypoints) const;

 private:
  std::filesystem::path masks_;
  std::filesystem::path overlays_;
  OverlayClasses classes_;
  cv::Mat mask_;  // reused
};

}  // namespace pspslam
