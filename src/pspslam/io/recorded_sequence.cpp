#include "pspslam/io/recorded_sequence.h"

#include <opencv2/imgproc.hpp>
#include <ostream>
#include <system_error>

#include "pspslam/core/error.h"
#include "pspslam/io/image_files.h"

namespace pspslam {

std::string to_string(SequenceLayout layout) {
  switch (layout) {
    case SequenceLayout::kitti:
      return "kitti";
    case SequenceLayout::euroc:
      return "euroc";
    case SequenceLayout::tum:
      break;
  }
  return "tum";
}

RecordedSequence::RecordedSequence(const std::filesystem::path& dir, const SequenceOptions& options,
                                   SensorType sensor)
    : dir_(dir), options_(options), sensor_(sensor) {
  options_.sensor = sensor;
}

void RecordedSequence::keep_present_frames(std::vector<FrameFiles> listed_frames,
                                           const std::vector<std::string>& listed_files) {
  // A listed name the file system cannot even look up (too long, say) is a missing file, not an
  // exception (found by fuzz/fuzz_sequence_lists).
  const auto present = [&](const std::string& file) {
    std::error_code ec;
    return std::filesystem::exists(dir_ / file, ec) && !ec;
  };
  std::string first_missing;
  for (const std::string& file : listed_files) {
    if (present(file)) continue;
    if (missing_files_++ == 0) first_missing = file;
  }
  for (FrameFiles& frame : listed_frames) {
    if (missing_files_ > 0 && (!present(frame.rgb_file) || !present(frame.depth_file))) {
      ++skipped_frames_;
      continue;
    }
    frames_.push_back(std::move(frame));
  }
  if (missing_files_ > 0) {
    warning_ = dir_.string() + ": " + std::to_string(missing_files_) +
               " listed files are missing; skipped " + std::to_string(skipped_frames_) +
               " frames (first: " + first_missing + ")";
    if (options_.warnings != nullptr) *options_.warnings << "warning: " << warning_ << "\n";
  }
}

std::optional<std::filesystem::path> RecordedSequence::config_path() const {
  const std::filesystem::path config = dir_ / "config.yaml";
  if (std::filesystem::exists(config)) return config;
  return std::nullopt;
}

InputFrame RecordedSequence::load(size_t i) const {
  const FrameFiles& files = frames_.at(i);
  InputFrame frame;
  frame.index = i;
  frame.timestamp = files.rgb_timestamp;
  frame.depth_timestamp = files.depth_timestamp;
  frame.name = files.rgb_file;
  const std::filesystem::path rgb_path = dir_ / files.rgb_file;
  const std::filesystem::path second_path = dir_ / files.depth_file;
  frame.bgr = read_color_image(rgb_path);
  switch (sensor_) {
    case SensorType::stereo:
      frame.right = read_right_image(second_path);
      check_same_size(frame.bgr, rgb_path, frame.right, second_path);
      break;
    case SensorType::rgbd:
      frame.depth = read_depth_image(second_path, options_.depth_factor, options_.depth_shift_x,
                                     options_.depth_shift_y);
      check_same_size(frame.bgr, rgb_path, frame.depth, second_path);
      break;
    case SensorType::monocular:
      break;
  }
  to_camera_images(frame);
  if (options_.load_gray) cv::cvtColor(frame.bgr, frame.gray, cv::COLOR_BGR2GRAY);
  return frame;
}

}  // namespace pspslam
