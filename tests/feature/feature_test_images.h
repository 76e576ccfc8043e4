#pragma once

#include <opencv2/core.hpp>

#include <filesystem>

namespace pspslam::testing {

// A deterministic 640x480 (by default) grey image full of corners at many scales: overlapping
// rectangles, ellipses and lines of random grey levels, lightly smoothed. Lets the extractor tests
// run without ../shared.
cv::Mat make_textured_image(int width = 640, int height = 480, unsigned seed = 7);

// Frame `index` (sorted by name) of shared/data/bonn_crowd_dev/rgb as a grey image.
cv::Mat load_bonn_gray_frame(const std::filesystem::path& shared, int index);

}  // namespace pspslam::testing
