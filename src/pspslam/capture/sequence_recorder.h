#pragma once

#include <cstddef>
#include <filesystem>
#include <fstream>

#include "pspslam/io/input_frame.h"

namespace pspslam {

// Writes frames as a TUM-layout sequence that TumSequence reads back (`pspslam record`):
//   rgb/<t>.png     colour, 8-bit BGR PNG
//   depth/<t>.png   depth, 16-bit PNG in units of 1/depth_factor m (0 = no reading)
//   rgb.txt, depth.txt   `timestamp filename` lists
//   config.yaml     a copy of the camera config the frames were taken with (its depth_factor is
//                   the one the depth images were written with)
// Each frame's images are written before its list lines, and the lists are flushed per frame,
// so a recording stopped at any point (Ctrl-C, unplugged camera) is a complete, valid sequence.
class SequenceRecorder {
 public:
  // `dir` must be empty or not exist yet. Errors name --out and the file.
  SequenceRecorder(const std::filesystem::path& dir, const std::filesystem::path& config_file,
                   double depth_factor);

  void add(const InputFrame& frame);
  size_t frames() const { return frames_; }

 private:
  std::filesystem::path dir_;
  double depth_factor_;
  std::ofstream rgb_list_;
  std::ofstream depth_list_;
  size_t frames_ = 0;
};

}  // namespace pspslam
