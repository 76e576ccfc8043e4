#pragma once

#include <filesystem>
#include <memory>

#include "pspslam/config/config.h"
#include "pspslam/io/frame_source.h"

namespace pspslam {

struct RunOptions;

// What a run reads: its frames and the camera config they are processed with.
struct RunInput {
  std::filesystem::path config_file;
  SystemConfig config;
  std::unique_ptr<FrameSource> source;
};

// The one place that turns what a user named into frames, whatever the input:
//  - options.sequence: a recorded folder, its layout detected (TUM/Bonn, KITTI, EuRoC;
//    io/sequence_setup.h), played as a SequenceSource, paced with options.system.dynamic.realtime;
//  - options.camera: a live camera (capture/camera_spec.h; config: options.config, else the
//    camera's preset);
//  - options.video: a video file or camera index through cv::VideoCapture, monocular (needs
//    options.config for the intrinsics).
// options.sensor overrides the config's camera.type. Every module's config section is checked
// before the input opens. Throws pspslam::Error naming the file or the device.
RunInput open_run_input(const RunOptions& options);

}  // namespace pspslam
