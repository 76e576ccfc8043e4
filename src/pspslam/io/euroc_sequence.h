#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "pspslam/io/euroc_calibration.h"
#include "pspslam/io/recorded_sequence.h"

namespace pspslam {

// The EuRoC MAV layout: DIR/mav0 (or DIR itself when it is mav0) with cam0/ and cam1/, each
// data.csv (`#timestamp [ns],filename`), data/<file> and sensor.yaml. Stereo rectifies the pair
// from the two sensor.yaml (cv::stereoRectify + remap) as frames load, pairing cam0 and cam1 rows
// by equal timestamps; monocular reads cam0 alone and undistorts it (Undistortion). A folder
// without cam1/data.csv is monocular unless SequenceOptions::sensor says otherwise. Ground
// truth, when mav0/state_groundtruth_estimate0/data.csv exists, is moved from the body (IMU)
// onto the camera load() delivers. Missing image files are counted once and their frames skipped.
class EurocSequence final : public RecordedSequence {
 public:
  static EurocSequence open(const std::filesystem::path& dir, const SequenceOptions& options = {});
  // Whether DIR (or DIR/mav0) holds the right camera's list (cam1/data.csv).
  static bool has_right_camera(const std::filesystem::path& dir);

  SequenceLayout layout() const override { return SequenceLayout::euroc; }
  std::string listing() const override;
  // The rectified left camera (stereo) or the undistorted cam0 (monocular), at cam0's rate_hz.
  std::optional<LayoutCamera> layout_camera() const override;

  // cam0's calibration as sensor.yaml gives it.
  const EurocCamera& left_camera() const { return left_; }
  // The rectification of the pair (stereo only; null for monocular).
  const std::shared_ptr<const StereoRectification>& rectification() const { return rectification_; }

 private:
  using RecordedSequence::RecordedSequence;
  void to_camera_images(InputFrame& frame) const override;
  void list_pairs(const std::filesystem::path& mav);
  void list_left_images(const std::filesystem::path& mav);

  EurocCamera left_;
  std::shared_ptr<const StereoRectification> rectification_;
  std::shared_ptr<const Undistortion> undistortion_;
};

}  // namespace pspslam
