#pragma once

#include <chrono>
#include <cstddef>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "pspslam/core/types.h"
#include "pspslam/io/association.h"

namespace pspslam {

struct SequenceOptions {
  // Depth image units per metre (5000 for TUM RGB-D and Bonn; take it from CameraConfig).
  double depth_factor = 5000.0;
  // CameraConfig's depth registration shift: frame.depth(u, v) = depth image at (u + x, v + y).
  int depth_shift_x = 0;
  int depth_shift_y = 0;
  // Colour/depth association window, as associate.py's --max_difference.
  double max_difference = kDefaultMaxTimeDifference;
  // Where open() prints its one-line missing-files warning; nullptr keeps it silent (the text
  // stays available through RgbdSequence::warning()).
  std::ostream* warnings = &std::cerr;
  // RgbdFrame::gray is filled only when asked (saves a colour conversion per frame).
  bool load_gray = true;
};

// One associated colour/depth frame in memory.
struct RgbdFrame {
  size_t index = 0;           // position in the sequence (0 .. size()-1)
  Timestamp timestamp = 0.0;  // colour timestamp
  Timestamp depth_timestamp = 0.0;
  cv::Mat bgr;    // CV_8UC3
  cv::Mat gray;   // CV_8UC1 (empty unless SequenceOptions::load_gray)
  cv::Mat depth;  // CV_32FC1 metres, 0 = no reading
  // The colour image's file relative to its sequence ("rgb/1.5.png"); per-frame pictures are
  // named after it. A live camera frame is named as `pspslam record` would store it.
  std::string name;
  // When the frame reached the run from the camera's point of view: a paced sequence's due time
  // (`--realtime`), a live camera's pairing time on the driver thread. Empty for an unpaced
  // sequence, where a frame has no arrival to measure from. The run measures the time from here
  // to the frame's pose (stats.json `latency`).
  std::optional<std::chrono::steady_clock::time_point> arrival;
};

// File names of one associated frame, relative to the sequence directory as listed.
struct FrameFiles {
  Timestamp rgb_timestamp = 0.0;
  std::string rgb_file;
  Timestamp depth_timestamp = 0.0;
  std::string depth_file;
};

// An RGB-D sequence in the TUM RGB-D layout (also used by the Bonn dataset):
//   rgb.txt, depth.txt  `timestamp filename` lists, associated like associate.py, or
//   associations.txt    `t_rgb rgb_file t_depth depth_file` when present (used as given),
//   groundtruth.txt     optional TUM trajectory,
//   config.yaml         optional camera config written by `pspslam synth`.
// open() reads the lists only; images are decoded by load(i), so a long sequence costs no memory.
// Frames whose colour or depth file is missing are skipped with one warning for the whole
// sequence (the Bonn sequences list depth files that were never recorded).
class RgbdSequence {
 public:
  // Errors: "<dir>: sequence directory not found", "<dir>: no rgb.txt / depth.txt or
  // associations.txt", malformed lines ("<file>:<line>: expected 'timestamp filename', got N
  // fields", ...), a malformed groundtruth.txt, no frame left.
  static RgbdSequence open(const std::filesystem::path& dir, const SequenceOptions& options = {});

  size_t size() const { return frames_.size(); }
  bool empty() const { return frames_.empty(); }
  Timestamp timestamp(size_t i) const { return frames_.at(i).rgb_timestamp; }
  const FrameFiles& files(size_t i) const { return frames_.at(i); }

  // Decodes frame i. Errors name the file: unreadable/empty image, depth not 16-bit
  // single-channel, colour and depth of different size.
  RgbdFrame load(size_t i) const;

  const std::filesystem::path& directory() const { return dir_; }
  const SequenceOptions& options() const { return options_; }

  // DIR/config.yaml when the sequence ships its own camera config (synthetic sequences do).
  std::optional<std::filesystem::path> config_path() const;

  // groundtruth.txt when present.
  const std::optional<Trajectory>& ground_truth() const { return ground_truth_; }

  // Book-keeping of open(), for reports.
  bool used_associations_file() const { return used_associations_file_; }
  size_t listed_rgb() const { return listed_rgb_; }
  size_t listed_depth() const { return listed_depth_; }
  size_t missing_files() const { return missing_files_; }
  size_t skipped_frames() const { return skipped_frames_; }
  // The missing-files warning (without "warning: "), empty when nothing is missing.
  const std::string& warning() const { return warning_; }

 private:
  RgbdSequence() = default;

  std::filesystem::path dir_;
  SequenceOptions options_;
  std::vector<FrameFiles> frames_;
  std::optional<Trajectory> ground_truth_;
  bool used_associations_file_ = false;
  size_t listed_rgb_ = 0;
  size_t listed_depth_ = 0;
  size_t missing_files_ = 0;
  size_t skipped_frames_ = 0;
  std::string warning_;
};

// Reads a 16-bit depth PNG as CV_32FC1 metres (value / depth_factor; 0 stays 0 = no reading),
// shifted so that result(u, v) = image(u + shift_x, v + shift_y) (pixels shifted in from beyond
// the border have no reading).
// Errors: "<file>: cannot read depth image (missing, empty or not an image)",
// "<file>: depth image must be 16-bit single-channel (got 8-bit, 1 channel)".
cv::Mat read_depth_image(const std::filesystem::path& file, double depth_factor, int shift_x = 0,
                         int shift_y = 0);

// Reads a colour image (PNG, JPEG, ...) as CV_8UC3 BGR.
cv::Mat read_color_image(const std::filesystem::path& file);

}  // namespace pspslam
