#pragma once

#include <filesystem>

#include <opencv2/core.hpp>

namespace pspslam {

// Reads a 16-bit depth PNG as CV_32FC1 metres (value / depth_factor; 0 stays 0 = no reading),
// shifted so that result(u, v) = image(u + shift_x, v + shift_y) (pixels shifted in from beyond
// the border have no reading).
// Errors: "<file>: cannot read depth image (missing, empty or not an image)",
// "<file>: depth image must be 16-bit single-channel (got 8-bit, 1 channel)".
cv::Mat read_depth_image(const std::filesystem::path& file, double depth_factor, int shift_x = 0,
                         int shift_y = 0);
// The conversion of read_depth_image on a 16-bit depth image already in memory (CV_16UC1).
cv::Mat depth_to_metres(const cv::Mat& raw, double depth_factor, int shift_x = 0, int shift_y = 0);

// Reads a colour image (PNG, JPEG, ...) as CV_8UC3 BGR; a grey image loads as three equal
// channels. Error: "<file>: cannot read colour image (missing, empty or not an image)".
cv::Mat read_color_image(const std::filesystem::path& file);

// Reads the right image of a stereo pair as CV_8UC1.
// Error: "<file>: cannot read right image (missing, empty or not an image)".
cv::Mat read_right_image(const std::filesystem::path& file);

// Throws "<first> is WxH but <second> is WxH" unless the two images of one frame (colour and
// depth, left and right) have the same size.
void check_same_size(const cv::Mat& first, const std::filesystem::path& first_file,
                     const cv::Mat& second, const std::filesystem::path& second_file);

// The file name of a per-frame picture of the colour image `rgb_file` (InputFrame::name):
// "rgb/1548339828.32144.jpg" -> "1548339828.32144.png". What `--save-masks` and
// `--save-overlays` write and `--semantic-masks` reads.
std::filesystem::path per_frame_png_name(const std::filesystem::path& rgb_file);

}  // namespace pspslam
