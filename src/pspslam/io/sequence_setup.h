#pragma once

#include <filesystem>
#include <iostream>
#include <optional>
#include <string>

#include "pspslam/config/config.h"
#include "pspslam/io/rgbd_sequence.h"

namespace pspslam {

// A sequence opened with the camera config it is to be processed with.
struct SequenceSetup {
  std::filesystem::path config_file;
  SystemConfig config;
  RgbdSequence sequence;
};

// What `pspslam run` (and anything else that processes a sequence) does first:
//  - the config is `config_file` when given, else DIR/config.yaml (synthetic sequences ship one);
//    with neither: Error "<DIR>: no camera config: --config was not given and <DIR>/config.yaml
//    does not exist (pass a preset, e.g. --config config/bonn.yaml)";
//  - the sequence is opened with the config's depth factor; the missing-files warning goes to
//    `warnings`.
//  - `sensor` (`pspslam run --sensor`) overrides the config's camera.type;
//  - a KITTI odometry folder (times.txt + calib.txt) is read as such: its camera is P0 of
//    calib.txt with P1's baseline, its size that of the first left image, its rate from
//    times.txt; the config (when given) supplies everything else (ORB) and its camera
//    intrinsics are replaced by the calibration's.
SequenceSetup open_sequence_with_config(const std::filesystem::path& dir,
                                        const std::optional<std::filesystem::path>& config_file,
                                        std::ostream* warnings = &std::cerr,
                                        std::optional<SensorType> sensor = std::nullopt);

// The camera.type a config is run as when `--sensor` says `sensor`. Switching needs what the
// other sensor needs: "--sensor stereo: <file> gives no camera.baseline" (stereo needs a
// baseline), "--sensor rgbd: <file> describes a stereo camera (no depth_factor)".
void apply_sensor_override(SystemConfig& config, SensorType sensor,
                           const std::filesystem::path& config_file);

// Multi-line summary: frames, skipped frames, time span, ground truth, config.
std::string describe_sequence(const SequenceSetup& setup);

}  // namespace pspslam
