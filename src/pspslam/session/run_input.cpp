#include "pspslam/session/run_input.h"

#include <spdlog/spdlog.h>

#include <iostream>

#include "pspslam/capture/camera_spec.h"
#include "pspslam/core/error.h"
#include "pspslam/io/sequence_setup.h"
#include "pspslam/io/sequence_source.h"
#include "pspslam/io/video_source.h"
#include "pspslam/session/run_options.h"
#include "pspslam/system/system.h"

namespace pspslam {
namespace {

RunInput open_sequence(const RunOptions& options) {
  SequenceSetup setup = open_sequence_with_config(
      options.sequence, options.config,
      spdlog::should_log(spdlog::level::warn) ? &std::cerr : nullptr, options.sensor);
  check_config_sections(setup.config);  // before a preload decodes every frame
  RunInput input{setup.config_file, setup.config, nullptr};
  input.source = std::make_unique<SequenceSource>(std::move(setup), options.max_frames,
                                                  options.system.dynamic.realtime, options.preload,
                                                  options.start_frame);
  return input;
}

RunInput open_live_camera(const RunOptions& options) {
  const CameraSpec spec = parse_camera_spec(options.camera);
  RunInput input;
  input.config_file = options.config.value_or(camera_config_preset(spec));
  input.config = load_config(input.config_file);
  if (options.sensor) apply_sensor_override(input.config, *options.sensor, input.config_file);
  check_config_sections(input.config);
  input.source = open_camera(spec);
  return input;
}

RunInput open_video_input(const RunOptions& options) {
  if (!options.config) throw Error("--video needs --config for the camera's intrinsics");
  RunInput input;
  input.config_file = *options.config;
  input.config = load_config(input.config_file);
  apply_sensor_override(input.config, SensorType::monocular, input.config_file);
  check_config_sections(input.config);
  input.source = open_video(options.video, input.config.camera.fps);
  return input;
}

}  // namespace

RunInput open_run_input(const RunOptions& options) {
  if (!options.camera.empty()) return open_live_camera(options);
  if (!options.video.empty()) return open_video_input(options);
  return open_sequence(options);
}

}  // namespace pspslam
