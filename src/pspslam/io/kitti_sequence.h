#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "pspslam/io/recorded_sequence.h"

namespace pspslam {

// KITTI odometry calibration (calib.txt): the rectified left camera (P0) and the baseline from
// P1's translation (P1[0][3] = -fx * baseline).
struct KittiCalibration {
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
  double baseline = 0.0;  // 0 when read for the left camera alone
};
// Errors name file:line: "P0: expected 12 numbers, got N", a non-number, a missing P0 or P1,
// a P1 whose fx differs from P0's (not a rectified pair), a baseline that is not positive.
// `right_camera` false reads P0 alone (a monocular run): P1 is neither needed nor checked.
KittiCalibration read_kitti_calibration(const std::filesystem::path& file,
                                        bool right_camera = true);

// The KITTI odometry layout: times.txt (one timestamp in seconds per line), calib.txt, image_0/
// and image_1/ (left and right, %06d.png, one per line of times.txt), and optionally poses.txt
// (KITTI's 3x4 row-major camera-to-world per line, one per frame) as ground truth. Stereo reads
// both image folders, monocular image_0/ alone (a folder without image_1/ is monocular unless
// SequenceOptions::sensor says otherwise). Missing image files are counted and their frames
// skipped with one warning, as for TUM.
class KittiSequence final : public RecordedSequence {
 public:
  static KittiSequence open(const std::filesystem::path& dir, const SequenceOptions& options = {});
  // Whether DIR holds the right camera's images (image_1/).
  static bool has_right_images(const std::filesystem::path& dir);

  SequenceLayout layout() const override { return SequenceLayout::kitti; }
  std::string listing() const override;
  // P0 of calib.txt (and P1's baseline for stereo), the size of the first left image and the
  // mean rate of times.txt.
  std::optional<LayoutCamera> layout_camera() const override;

  const KittiCalibration& calibration() const { return calibration_; }

 private:
  using RecordedSequence::RecordedSequence;

  KittiCalibration calibration_;
};

}  // namespace pspslam
