#include "pspslam/io/image_files.h"

#include <opencv2/imgcodecs.hpp>
#include <string>

#include "pspslam/core/error.h"

namespace pspslam {
namespace {

std::string describe_type(const cv::Mat& image) {
  std::string depth;
  switch (image.depth()) {
    case CV_8U:
      depth = "8-bit";
      break;
    case CV_8S:
      depth = "8-bit signed";
      break;
    case CV_16U:
      depth = "16-bit";
      break;
    case CV_16S:
      depth = "16-bit signed";
      break;
    case CV_32F:
      depth = "32-bit float";
      break;
    default:
      depth = "type " + std::to_string(image.depth());
      break;
  }
  const int channels = image.channels();
  return depth + ", " + std::to_string(channels) + (channels == 1 ? " channel" : " channels");
}

}  // namespace

cv::Mat read_depth_image(const std::filesystem::path& file, double depth_factor, int shift_x,
                         int shift_y) {
  const cv::Mat raw = cv::imread(file.string(), cv::IMREAD_UNCHANGED);
  if (raw.empty()) {
    throw Error(file.string() + ": cannot read depth image (missing, empty or not an image)");
  }
  if (raw.type() != CV_16UC1) {
    throw Error(file.string() + ": depth image must be 16-bit single-channel (got " +
                describe_type(raw) + ")");
  }
  return depth_to_metres(raw, depth_factor, shift_x, shift_y);
}

cv::Mat depth_to_metres(const cv::Mat& raw, double depth_factor, int shift_x, int shift_y) {
  cv::Mat metres;
  if (shift_x == 0 && shift_y == 0) {
    raw.convertTo(metres, CV_32F, 1.0 / depth_factor);
    return metres;
  }
  // One conversion of the overlapping rectangle into place; the strip shifted in stays 0.
  metres = cv::Mat::zeros(raw.size(), CV_32F);
  const cv::Rect image(0, 0, raw.cols, raw.rows);
  const cv::Rect source = image & (image + cv::Point(shift_x, shift_y));
  if (!source.empty()) {
    cv::Mat target = metres(source - cv::Point(shift_x, shift_y));
    raw(source).convertTo(target, CV_32F, 1.0 / depth_factor);
  }
  return metres;
}

cv::Mat read_color_image(const std::filesystem::path& file) {
  cv::Mat bgr = cv::imread(file.string(), cv::IMREAD_COLOR);
  if (bgr.empty()) {
    throw Error(file.string() + ": cannot read colour image (missing, empty or not an image)");
  }
  return bgr;
}

cv::Mat read_right_image(const std::filesystem::path& file) {
  cv::Mat right = cv::imread(file.string(), cv::IMREAD_GRAYSCALE);
  if (right.empty()) {
    throw Error(file.string() + ": cannot read right image (missing, empty or not an image)");
  }
  return right;
}

void check_same_size(const cv::Mat& first, const std::filesystem::path& first_file,
                     const cv::Mat& second, const std::filesystem::path& second_file) {
  if (first.size() == second.size()) return;
  throw Error(first_file.string() + " is " + std::to_string(first.cols) + "x" +
              std::to_string(first.rows) + " but " + second_file.string() + " is " +
              std::to_string(second.cols) + "x" + std::to_string(second.rows));
}

std::filesystem::path per_frame_png_name(const std::filesystem::path& rgb_file) {
  return rgb_file.filename().stem().string() + ".png";
}

}  // namespace pspslam
