#pragma once

#include <chrono>
#include <cstddef>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "pspslam/core/types.h"
#include "pspslam/io/association.h"
#include "pspslam/io/euroc.h"

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
  // InputFrame::gray is filled only when asked (saves a colour conversion per frame).
  bool load_gray = true;
  // A rectified stereo pair per frame instead of colour + depth: the TUM-style lists are
  // rgb.txt (left) and right.txt (right, CV_8UC1 in InputFrame::right); no depth is read.
  bool stereo = false;
  // Colour images only (a monocular run on an RGB-D folder): rgb.txt alone is read, every listed
  // colour image is a frame, and no depth is listed, associated or loaded.
  bool colour_only = false;
};

// How a sequence folder is laid out (detected by open_sequence_with_config).
enum class SequenceLayout {
  tum,    // rgb.txt + depth.txt or associations.txt (or rgb.txt + right.txt for stereo)
  kitti,  // KITTI odometry: times.txt, calib.txt, image_0/, image_1/, optional poses.txt
  euroc,  // EuRoC MAV: mav0/cam0, mav0/cam1 (data.csv, data/, sensor.yaml), unrectified
};
std::string to_string(SequenceLayout layout);

// The images of one moment as the sensor delivered them, whatever the sensor: colour with depth
// (RGB-D), colour with the rectified right image (stereo) or colour alone (monocular).
struct InputFrame {
  size_t index = 0;           // position in the sequence (0 .. size()-1)
  Timestamp timestamp = 0.0;  // colour timestamp
  Timestamp depth_timestamp = 0.0;
  cv::Mat bgr;    // CV_8UC3
  cv::Mat gray;   // CV_8UC1 (empty unless SequenceOptions::load_gray)
  cv::Mat depth;  // CV_32FC1 metres, 0 = no reading (empty for a stereo pair)
  cv::Mat right;  // stereo only: the rectified right image, CV_8UC1 (empty for RGB-D)
  // The colour image's file relative to its sequence ("rgb/1.5.png"); per-frame pictures are
  // named after it (per_frame_png_name). A live camera frame is named as `pspslam record` would
  // store it.
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
  std::string rgb_file;  // colour, or the left image of a stereo pair
  Timestamp depth_timestamp = 0.0;
  std::string depth_file;  // depth, or the right image of a stereo pair
};

// KITTI odometry calibration (calib.txt): the rectified left camera (P0) and the baseline from
// P1's translation (P1[0][3] = -fx * baseline).
struct KittiCalibration {
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
  double baseline = 0.0;
};
// Errors name file:line: "P0: expected 12 numbers, got N", a non-number, a missing P0 or P1,
// a P1 whose fx differs from P0's (not a rectified pair), a baseline that is not positive.
KittiCalibration read_kitti_calibration(const std::filesystem::path& file);

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
  // KITTI odometry layout (stereo): times.txt (one timestamp in seconds per line), image_0/ and
  // image_1/ (left and right, %06d.png, one per line of times.txt), and optionally poses.txt
  // (KITTI's 3x4 row-major camera-to-world per line, one per frame) as ground truth. Missing
  // image files are counted and their frames skipped with one warning, as for TUM.
  static RgbdSequence open_kitti(const std::filesystem::path& dir,
                                 const SequenceOptions& options = {});
  // EuRoC MAV layout (stereo): DIR/mav0 (or DIR itself when it is mav0) with cam0/ and cam1/,
  // each data.csv (`#timestamp [ns],filename`), data/<file> and sensor.yaml. The pair is
  // rectified from the two sensor.yaml (cv::stereoRectify + remap) as frames load; cam0 and cam1
  // rows are paired by equal timestamps. Ground truth, when
  // mav0/state_groundtruth_estimate0/data.csv exists, is moved from the body (IMU) onto the
  // rectified left camera. Missing image files are counted once and their frames skipped.
  static RgbdSequence open_euroc(const std::filesystem::path& dir,
                                 const SequenceOptions& options = {});
  // The rectification of an EuRoC pair (null for rectified layouts).
  const std::shared_ptr<const StereoRectification>& rectification() const { return rectification_; }

  size_t size() const { return frames_.size(); }
  bool empty() const { return frames_.empty(); }
  Timestamp timestamp(size_t i) const { return frames_.at(i).rgb_timestamp; }
  const FrameFiles& files(size_t i) const { return frames_.at(i); }

  // Decodes frame i. Errors name the file: unreadable/empty image, depth not 16-bit
  // single-channel, colour and depth of different size.
  InputFrame load(size_t i) const;

  const std::filesystem::path& directory() const { return dir_; }
  const SequenceOptions& options() const { return options_; }

  // DIR/config.yaml when the sequence ships its own camera config (synthetic sequences do).
  std::optional<std::filesystem::path> config_path() const;

  // groundtruth.txt when present.
  const std::optional<Trajectory>& ground_truth() const { return ground_truth_; }

  SequenceLayout layout() const { return layout_; }
  bool stereo() const { return options_.stereo; }

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
  // Keeps the frames whose files all exist; counts the missing listed files once and warns.
  void keep_present_frames(std::vector<FrameFiles> associated,
                           const std::vector<std::string>& listed_files);

  std::filesystem::path dir_;
  SequenceOptions options_;
  std::vector<FrameFiles> frames_;
  std::optional<Trajectory> ground_truth_;
  SequenceLayout layout_ = SequenceLayout::tum;
  std::shared_ptr<const StereoRectification> rectification_;
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
// The conversion of read_depth_image on a 16-bit depth image already in memory (CV_16UC1).
cv::Mat depth_to_metres(const cv::Mat& raw, double depth_factor, int shift_x = 0, int shift_y = 0);

// Reads a colour image (PNG, JPEG, ...) as CV_8UC3 BGR.
cv::Mat read_color_image(const std::filesystem::path& file);

// The file name of a per-frame picture of the colour image `rgb_file` (InputFrame::name):
// "rgb/1548339828.32144.jpg" -> "1548339828.32144.png". What `--save-masks` and
// `--save-overlays` write and `--semantic-masks` reads.
std::filesystem::path per_frame_png_name(const std::filesystem::path& rgb_file);

}  // namespace pspslam
