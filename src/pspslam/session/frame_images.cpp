#include "pspslam/session/frame_images.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "pspslam/core/error.h"
#include "pspslam/io/image_files.h"

namespace pspslam {
namespace {

void write_png(const std::filesystem::path& file, const cv::Mat& image) {
  bool written = false;
  try {
    written = cv::imwrite(file.string(), image);
  } catch (const cv::Exception& e) {
    throw Error(file.string() + ": cannot write image: " + e.what());
  }
  if (!written) throw Error(file.string() + ": cannot write image");
}

}  // namespace

void FrameImageWriter::write_mask(const std::filesystem::path& rgb_file,
                                  const cv::Mat& dynamic_mask, cv::Size size) {
  if (dynamic_mask.empty()) {
    mask_.create(size, CV_8UC1);
    mask_.setTo(0);
  } else {
    cv::compare(dynamic_mask, 0, mask_, cv::CMP_NE);  // any non-zero -> 255
  }
  write_png(masks_ / per_frame_png_name(rgb_file), mask_);
}

void FrameImageWriter::write_overlay(const std::filesystem::path& rgb_file, const cv::Mat& bgr,
                                     const cv::Mat& labels,
                                     std::span<const KeypointRecord> keypoints) const {
  write_png(overlays_ / per_frame_png_name(rgb_file),
            draw_keypoint_overlay(bgr, labels, classes_, keypoints));
}

}  // namespace pspslam
