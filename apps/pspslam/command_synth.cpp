#include <chrono>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "commands.h"
#include "flag_checks.h"
#include "pspslam/core/error.h"
#include "pspslam/core/output_paths.h"
#include "pspslam/core/progress.h"
#include "pspslam/synth/occupancy_truth.h"
#include "pspslam/synth/scene.h"
#include "pspslam/synth/sequence_writer.h"

namespace pspslam::cli {

namespace {

struct SynthFlags {
  SynthOptions options;
  std::string trajectory = "handheld";
  std::string depth_noise = "on";
  std::string sensor = "ideal";
  std::vector<std::string> no_faults;
  std::string out;
  std::string layout = "tum";
  double occupancy_truth = 0.0;  // cell size of the occupancy truth; 0 = none
};

// Where the sequence goes, how long it is and what moves in it.
void add_scene_options(CLI::App* app, SynthFlags& flags) {
  SynthOptions& options = flags.options;
  app->add_option("--out", flags.out, "output directory (created when missing)")->required();
  app->add_option("--frames", options.frames, "number of frames at 30 Hz")
      ->check(in_range(size_t{1}, size_t{1000000}))
      ->capture_default_str();
  app->add_option("--bodies", options.bodies, "people walking around the room (0 = static twin)")
      ->check(in_range(0, kMaxBodies))
      ->capture_default_str();
  app->add_option("--seed", options.seed, "random seed: same seed, same bytes")
      ->check(in_range(uint64_t{0}, uint64_t{4294967295}))
      ->capture_default_str();
  app->add_option("--stand-seconds", options.stand_seconds,
                  "people stand where they start for this long, then walk")
      ->check(in_range(0.0, 3600.0))
      ->capture_default_str();
  app->add_option("--trajectory", flags.trajectory, "camera motion")
      ->check(CLI::IsMember({"handheld", "loop"}))
      ->capture_default_str();
  app->add_option("--loop-turns", options.loop_turns,
                  "turns of the loop trajectory (1.08 revisits the start briefly; 1.5 gives half "
                  "a turn of revisit, enough for covisibility-consistent loop detection; a patrol "
                  "of hours takes hundreds)")
      ->check(in_range(0.01, 1000.0))
      ->capture_default_str();
}

// The camera the frames look as if taken with.
void add_sensor_options(CLI::App* app, SynthFlags& flags) {
  app->add_option("--depth-noise", flags.depth_noise,
                  "Kinect-like noise and holes (off = exact depth)")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str();
  app->add_option("--sensor", flags.sensor,
                  "camera model. ideal: registered, synchronised, global shutter, no distortion "
                  "(noise per --depth-noise). kinect: a hand-held Kinect v1 as the Bonn and TUM "
                  "recordings have it (depth noise ~z^2 quantised in disparity, holes, depth up to "
                  "+-16 ms off colour, rolling shutter, motion blur, exposure changes, lens "
                  "distortion, the Bonn clip's speeds, marker-body ground truth + "
                  "body_to_camera.txt). Accuracy experiments should use kinect: ideal errors are "
                  "far below any real recording's")
      ->check(CLI::IsMember({"ideal", "kinect"}))
      ->capture_default_str();
  std::string fault_list;
  for (const std::string& name : synth::KinectFaults::names()) {
    fault_list += (fault_list.empty() ? "" : ", ") + name;
  }
  app->add_option("--no-fault", flags.no_faults,
                  "with --sensor kinect: switch one fault off (repeatable), to measure its share "
                  "of the error: " +
                      fault_list)
      ->check(CLI::IsMember(synth::KinectFaults::names()));
}

// Carried boxes, a right camera, the folder layout and the writer threads.
void add_extra_options(CLI::App* app, SynthFlags& flags) {
  SynthOptions& options = flags.options;
  app->add_option("--carried-objects", options.carried_objects, "people carrying a box (label 100)")
      ->check(in_range(0, kMaxBodies))
      ->capture_default_str();
  app->add_option("--stereo", options.stereo_baseline,
                  "also render a rectified right camera BASELINE_M metres to the right and write "
                  "the stereo config (right/, right.txt; config_rgbd.yaml keeps the RGB-D one)");
  app->add_option("--layout", flags.layout,
                  "tum, kitti or euroc (both need --stereo): KITTI odometry (image_0/, "
                  "image_1/, times.txt, calib.txt, poses.txt) or EuRoC MAV (mav0/cam0, cam1, "
                  "state_groundtruth_estimate0)")
      ->check(CLI::IsMember({"tum", "kitti", "euroc"}))
      ->capture_default_str();
  app->add_option("--occupancy-truth", flags.occupancy_truth,
                  "also write the room's true occupancy at this cell size in metres "
                  "(occupancy_truth/: static, seen and swept cells, exact camera poses), for "
                  "scoring 'pspslam run --occupancy-truth'")
      ->check(in_range(0.005, 1.0));
  app->add_option("--threads", options.threads, "worker threads (0 = all cores)")
      ->check(in_range(0, 256))
      ->capture_default_str();
}

// The scene's options from the flags, checked.
SynthOptions synth_options(const SynthFlags& flags) {
  SynthOptions options = flags.options;
  options.trajectory = parse_synth_trajectory(flags.trajectory);
  options.depth_noise = flags.depth_noise == "on";
  options.sensor = parse_synth_sensor(flags.sensor);
  options.layout = flags.layout == "kitti"   ? SynthOptions::Layout::kitti
                   : flags.layout == "euroc" ? SynthOptions::Layout::euroc
                                             : SynthOptions::Layout::tum;
  if (!flags.no_faults.empty() && options.sensor != SynthSensor::kKinect) {
    throw Error("synth: flag --no-fault needs --sensor kinect");
  }
  for (const std::string& name : flags.no_faults) options.faults.set(name, false);
  options.validate();
  return options;
}

int synthesize(const SynthFlags& flags, const GlobalOptions& global) {
  const SynthOptions options = synth_options(flags);
  prepare_output_folder(flags.out, "--out");
  const auto start = std::chrono::steady_clock::now();
  const SyntheticScene scene(options);
  ProgressBar progress("synth", options.frames, std::cerr, !global.quiet);
  write_sequence(scene, flags.out, [&](size_t done) { progress.update(done); });
  progress.finish();
  if (flags.occupancy_truth > 0.0) {
    const OccupancyTruth truth =
        compute_occupancy_truth(scene, {.resolution = flags.occupancy_truth,
                                        .max_range_m = scene.system_config().camera.depth_threshold,
                                        .threads = options.threads});
    write_occupancy_truth(truth, std::filesystem::path(flags.out) / "occupancy_truth");
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "wrote " << options.frames << " frames (" << options.bodies << " bodies, "
            << to_string(options.trajectory) << ", " << to_string(options.sensor)
            << " sensor, seed " << options.seed << ") to " << flags.out << " in " << seconds
            << " s\n";
  return 0;
}

}  // namespace

Command add_synth_command(CLI::App& root) {
  CLI::App* app = root.add_subcommand(
      "synth",
      "render a synthetic dynamic RGB-D sequence.\n"
      "Writes TUM layout: rgb/, depth/ (16-bit, 5000 per metre), mask/ (0 static, 15 person, 100 "
      "carried object), groundtruth.txt and config.yaml, ready for 'pspslam run --sequence DIR'.");
  auto flags = std::make_shared<SynthFlags>();
  add_scene_options(app, *flags);
  add_sensor_options(app, *flags);
  add_extra_options(app, *flags);
  return {app, [flags](const GlobalOptions& global) { return synthesize(*flags, global); }};
}

}  // namespace pspslam::cli
