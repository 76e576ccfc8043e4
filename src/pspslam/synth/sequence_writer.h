#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>

#include "pspslam/core/types.h"
#include "pspslam/synth/scene.h"

namespace pspslam {

// Called from the calling thread after each finished frame with the number done so far.
using SynthProgress = std::function<void(size_t frames_done)>;

// Renders every frame and writes the TUM layout into `dir` (created when missing):
//   rgb/<ts>.png, depth/<ts>.png (16-bit, 5000 per metre, 0 = no reading), mask/<ts>.png
//   (8-bit kSynthLabel* values), rgb.txt, depth.txt, mask.txt, groundtruth.txt (camera-to-world),
//   config.yaml (save_config of synthetic_system_config()), info.yaml (generator parameters),
//   README.txt (what the files are), people.txt (with walking people: every person at every
//   frame, synth/people_truth.h; in every layout).
// With a stereo baseline also right/<ts>.png (8-bit grey, rectified right camera), right.txt,
// config.yaml for the stereo camera and config_rgbd.yaml for the RGB-D one. With the KITTI
// layout instead: image_0/, image_1/ (grey, %06d.png), times.txt, calib.txt, poses.txt,
// groundtruth.txt (TUM, the same poses) and info.yaml.
// Frames are rendered and encoded in parallel (options().threads workers); the output bytes do
// not depend on the thread count. Throws pspslam::Error naming the path that cannot be written.
void write_sequence(const SyntheticScene& scene, const std::filesystem::path& dir,
                    const SynthProgress& progress = {});
void write_sequence(const SynthOptions& options, const std::filesystem::path& dir,
                    const SynthProgress& progress = {});

// "1000000.033333": the 6-decimal timestamp used in file names and lists.
std::string format_timestamp(Timestamp timestamp);

}  // namespace pspslam
