// `pspslam record`: a live camera's frames written as a TUM-layout sequence (capture/
// sequence_recorder.h) that `pspslam run --sequence` reads back. Stops after --frames, on Ctrl-C
// (exit 0: the normal way to end an open-ended recording) or when the camera stops delivering
// (exit 4); the folder is complete and valid in every case.
#include <spdlog/spdlog.h>

#include <iostream>
#include <memory>
#include <string>

#include "commands.h"
#include "flag_checks.h"
#include "pspslam/capture/camera_spec.h"
#include "pspslam/capture/sequence_recorder.h"
#include "pspslam/config/config.h"
#include "pspslam/core/interrupt.h"

namespace pspslam::cli {
namespace {

struct RecordFlags {
  std::string camera;
  std::string out;
  std::string config;
  size_t frames = 0;
};

int record(const RecordFlags& flags, const GlobalOptions& global) {
  const CameraSpec spec = parse_camera_spec(flags.camera);
  const std::filesystem::path config_file =
      flags.config.empty() ? camera_config_preset(spec) : std::filesystem::path(flags.config);
  const SystemConfig config = load_config(config_file);
  SequenceRecorder recorder(flags.out, config_file, config.camera.depth_factor);
  InterruptGuard interrupt_guard;
  const std::unique_ptr<FrameSource> camera = open_camera(spec);
  std::cout << camera->describe() << "recording:    " << flags.out << " ("
            << (flags.frames > 0 ? std::to_string(flags.frames) + " frames" : "until Ctrl-C")
            << ", depth factor " << config.camera.depth_factor << ")\n";
  while (!interrupted() && (flags.frames == 0 || recorder.frames() < flags.frames)) {
    const std::optional<InputFrame> frame = camera->next();
    if (!frame) break;
    recorder.add(*frame);
    if (!global.quiet && recorder.frames() % 30 == 0)
      std::cerr << "\rrecorded " << recorder.frames() << " frames" << std::flush;
  }
  const FrameSourceStats stats = camera->stats();
  if (!global.quiet) std::cerr << "\n";
  std::cout << "recorded:     " << recorder.frames() << " frames, " << stats.dropped
            << " dropped (the disk was slower than the camera)\n";
  if (stats.disconnected) {
    spdlog::error("{}; {} holds the {} frames recorded before", stats.end_reason, flags.out,
                  recorder.frames());
    return kCameraLostExit;
  }
  return 0;
}

}  // namespace

Command add_record_command(CLI::App& root) {
  CLI::App* app = root.add_subcommand(
      "record",
      "record a live RGB-D camera as a TUM-layout sequence (rgb/, depth/ 16-bit PNG, rgb.txt,\n"
      "depth.txt, config.yaml) that `pspslam run --sequence` reads; Ctrl-C stops it and leaves a "
      "valid folder.");
  auto flags = std::make_shared<RecordFlags>();
  app->add_option("--camera", flags->camera, "camera: freenect[:INDEX] (Kinect v1, libfreenect)")
      ->required();
  app->add_option("--out", flags->out, "folder to create (must be empty or new)")->required();
  app->add_option("--frames", flags->frames, "stop after this many frames (0 = until Ctrl-C)")
      ->check(in_range(size_t{0}, size_t{1000000000}))
      ->capture_default_str();
  app->add_option("--config", flags->config,
                  "camera config YAML copied into the recording (default: the shipped preset, "
                  "config/kinect_v1.yaml); its depth_factor scales the depth PNGs");
  return {app, [flags](const GlobalOptions& global) { return record(*flags, global); }};
}

}  // namespace pspslam::cli
