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
SequenceSetup open_sequence_with_config(const std::filesystem::path& dir,
                                        const std::optional<std::filesystem::path>& config_file,
                                        std::ostream* warnings = &std::cerr);

// Multi-line summary: frames, skipped frames, time span, ground truth, config.
std::string describe_sequence(const SequenceSetup& setup);

}  // namespace pspslam
