#pragma once

#include <cstddef>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "pspslam/config/config.h"
#include "pspslam/core/types.h"
#include "pspslam/io/association.h"
#include "pspslam/io/input_frame.h"

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
  // stays available through RecordedSequence::warning()).
  std::ostream* warnings = &std::cerr;
  // InputFrame::gray is filled only when asked (saves a colour conversion per frame).
  bool load_gray = true;
  // What each frame holds: colour + depth (rgbd), a rectified pair (stereo) or the colour/left
  // image alone (monocular; only its list is read). Unset: the layout's own, rgbd for the TUM
  // layout, stereo for KITTI and EuRoC when the right camera's images are there, else monocular.
  std::optional<SensorType> sensor = std::nullopt;
};

// How a sequence folder is laid out (detect_sequence_layout).
enum class SequenceLayout {
  tum,    // rgb.txt + depth.txt or associations.txt (or rgb.txt + right.txt for stereo)
  kitti,  // KITTI odometry: times.txt, calib.txt, image_0/, image_1/, optional poses.txt
  euroc,  // EuRoC MAV: mav0/cam0, mav0/cam1 (data.csv, data/, sensor.yaml), unrectified
};
std::string to_string(SequenceLayout layout);

// File names of one frame, relative to the sequence directory as listed.
struct FrameFiles {
  Timestamp rgb_timestamp = 0.0;
  std::string rgb_file;  // colour, or the left image of a stereo pair
  Timestamp depth_timestamp = 0.0;
  std::string depth_file;  // depth, or the right image of a stereo pair; empty for monocular
};

// The camera of a layout that ships its own calibration (KITTI's calib.txt, EuRoC's
// sensor.yaml): the pinhole of the left image as load() delivers it (rectified or undistorted:
// no distortion left) and, for a stereo pair, the baseline.
struct LayoutCamera {
  cv::Size size;
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
  double baseline = 0.0;  // 0 for monocular
  double rate_hz = 0.0;   // the frame rate the layout gives; 0 when it gives none
};

// A recorded sequence in one of the folder layouts (TumSequence, KittiSequence, EurocSequence;
// sequence_setup.h opens the right one). open() reads the lists only; images are decoded by
// load(i), so a long sequence costs no memory. Frames whose listed files are missing are skipped
// with one warning for the whole sequence (the Bonn sequences list depth files that were never
// recorded).
class RecordedSequence {
 public:
  virtual ~RecordedSequence() = default;

  size_t size() const { return frames_.size(); }
  bool empty() const { return frames_.empty(); }
  Timestamp timestamp(size_t i) const { return frames_.at(i).rgb_timestamp; }
  const FrameFiles& files(size_t i) const { return frames_.at(i); }

  // Decodes frame i as the sensor() delivers it. Errors name the file: unreadable/empty image,
  // depth not 16-bit single-channel, the two images of a frame of different size.
  InputFrame load(size_t i) const;

  virtual SequenceLayout layout() const = 0;
  // What each frame holds (SequenceOptions::sensor, resolved by open()).
  SensorType sensor() const { return sensor_; }
  bool stereo() const { return sensor_ == SensorType::stereo; }

  // The lists read and how their frames were paired, for describe_sequence: "4 colour and 4
  // depth files listed, associated within 0.02 s".
  virtual std::string listing() const = 0;

  // The camera from the layout's own calibration (KITTI, EuRoC); none for the TUM layout.
  virtual std::optional<LayoutCamera> layout_camera() const { return std::nullopt; }

  const std::filesystem::path& directory() const { return dir_; }
  const SequenceOptions& options() const { return options_; }

  // DIR/config.yaml when the sequence ships its own camera config (synthetic sequences do).
  std::optional<std::filesystem::path> config_path() const;

  // The ground-truth trajectory when the folder has one, and its file (relative to directory()).
  const std::optional<Trajectory>& ground_truth() const { return ground_truth_; }
  const std::filesystem::path& ground_truth_file() const { return ground_truth_file_; }

  // Book-keeping of open(), for reports. listed_depth counts the depth or right images.
  size_t listed_rgb() const { return listed_rgb_; }
  size_t listed_depth() const { return listed_depth_; }
  size_t missing_files() const { return missing_files_; }
  size_t skipped_frames() const { return skipped_frames_; }
  // The missing-files warning (without "warning: "), empty when nothing is missing.
  const std::string& warning() const { return warning_; }

 protected:
  RecordedSequence(const std::filesystem::path& dir, const SequenceOptions& options,
                   SensorType sensor);
  // Copied and moved as the reader it is (TumSequence, ...), never sliced to the base.
  RecordedSequence(const RecordedSequence&) = default;
  RecordedSequence(RecordedSequence&&) = default;
  RecordedSequence& operator=(const RecordedSequence&) = default;
  RecordedSequence& operator=(RecordedSequence&&) = default;
  // Keeps the frames whose files all exist; counts the missing listed files once and warns.
  void keep_present_frames(std::vector<FrameFiles> listed_frames,
                           const std::vector<std::string>& listed_files);
  // Turns the images as the layout stores them into those of the camera it describes (EuRoC's
  // are rectified or undistorted here); the others are stored that way.
  virtual void to_camera_images(InputFrame& /*frame*/) const {}

  std::filesystem::path dir_;
  SequenceOptions options_;
  SensorType sensor_ = SensorType::rgbd;
  std::vector<FrameFiles> frames_;
  std::optional<Trajectory> ground_truth_;
  std::filesystem::path ground_truth_file_;
  size_t listed_rgb_ = 0;
  size_t listed_depth_ = 0;
  size_t missing_files_ = 0;
  size_t skipped_frames_ = 0;
  std::string warning_;
};

}  // namespace pspslam
