#pragma once

#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "pspslam/config/config.h"
#include "pspslam/io/recorded_sequence.h"

namespace pspslam {

// A sequence opened with the camera config it is to be processed with.
struct SequenceSetup {
  std::filesystem::path config_file;
  SystemConfig config;
  std::unique_ptr<const RecordedSequence> sequence;
};

// The layout of a sequence folder: KITTI odometry when it has times.txt and calib.txt, EuRoC MAV
// when it has mav0/cam0/data.csv (or is mav0 itself, with cam0/data.csv), else TUM.
SequenceLayout detect_sequence_layout(const std::filesystem::path& dir);

// What `pspslam run` (and anything else that processes a sequence) does first: detects the
// layout (detect_sequence_layout) and opens it with its reader (TumSequence, KittiSequence,
// EurocSequence), the missing-files warning going to `warnings`.
//  - TUM: the config is `config_file` when given, else DIR/config.yaml (synthetic sequences ship
//    one); with neither: Error "<DIR>: no camera config: --config was not given and
//    <DIR>/config.yaml does not exist (pass a preset, e.g. --config config/bonn.yaml)". The
//    sequence is read with the config's depth factor, as the config's camera.type, which
//    `sensor` (`pspslam run --sensor`) overrides (apply_sensor_override).
//  - KITTI and EuRoC calibrate themselves: the camera is the layout's (LayoutCamera), its size
//    that of the images as loaded, its rate from the layout; the config (when given) supplies
//    everything else (ORB) and its camera intrinsics are replaced by the calibration's. The
//    folder is read as a stereo pair when the right camera's images are there, as monocular
//    (left images alone) when they are not or when `sensor` says monocular.
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
