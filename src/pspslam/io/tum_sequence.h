#pragma once

#include <filesystem>
#include <string>

#include "pspslam/io/recorded_sequence.h"

namespace pspslam {

// A sequence in the TUM RGB-D layout (also used by the Bonn dataset and `pspslam synth`):
//   rgb.txt, depth.txt  `timestamp filename` lists, associated like associate.py, or
//   associations.txt    `t_rgb rgb_file t_depth depth_file` when present (used as given),
//   right.txt           instead of depth.txt for a rectified stereo pair (right image CV_8UC1),
//   groundtruth.txt     optional TUM trajectory,
//   config.yaml         optional camera config written by `pspslam synth`.
// Monocular reads rgb.txt alone: every listed colour image is a frame, no depth is listed,
// associated or loaded.
class TumSequence final : public RecordedSequence {
 public:
  // Errors: "<dir>: sequence directory not found", "<dir>: no rgb.txt / depth.txt or
  // associations.txt", malformed lines ("<file>:<line>: expected 'timestamp filename', got N
  // fields", ...), a malformed groundtruth.txt, no frame left.
  static TumSequence open(const std::filesystem::path& dir, const SequenceOptions& options = {});

  SequenceLayout layout() const override { return SequenceLayout::tum; }
  std::string listing() const override;

  bool used_associations_file() const { return used_associations_file_; }

 private:
  using RecordedSequence::RecordedSequence;
  // The frames of rgb.txt and depth.txt (or right.txt) as associate.py pairs them.
  void associate_lists();

  bool used_associations_file_ = false;
};

}  // namespace pspslam
