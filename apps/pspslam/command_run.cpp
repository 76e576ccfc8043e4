// `pspslam run`: SLAM on an RGB-D sequence, or on a live camera with --camera (capture/: the
// frames come from its FrameSource instead of the folder). This file only turns the flags into
// RunOptions; the run itself (frame loop, output files, statistics) is SequenceRunner
// (session/), which writes
// (per-frame masks and overlays with --save-masks / --save-overlays, session/frame_images.h)
// into OUT/
//   trajectory.txt   T_world_camera of every tracked frame (TUM), flushed per frame so an
//                    interrupted run leaves a valid file
//   lost_frames.txt  timestamps of frames that got no pose (not initialised yet or lost)
//   keyframes.txt    keyframe poses at the end (after local mapping)
//   trajectory_refined.txt  the final trajectory and the file to evaluate, written at the end
//                    (also on Ctrl-C): the frames of trajectory.txt moved with the BA-refined
//                    keyframes around them in time
//   timing.csv       per frame: extraction / tracking / local BA milliseconds, state, and the
//                    dynamic-scene stages (mask age, geometry time, masked keypoints), the
//                    map's keyframes and points, resident memory
//   stats.json       run summary: frames, lost frames, fps, per-module timing {median, mean,
//                    p95}, dynamic-feature totals, mode, mask latency, ATE (with ground truth);
//                    written also when the run is interrupted (Ctrl-C / SIGTERM)
#include <spdlog/fmt/fmt.h>

#include <opencv2/core/utility.hpp>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "commands.h"
#include "flag_checks.h"
#include "occupancy_flags.h"
#include "pspslam/config/config.h"
#include "pspslam/core/error.h"
#include "pspslam/core/shared_paths.h"
#include "pspslam/core/thread_priority.h"
#include "pspslam/semantic/segmenter.h"
#include "pspslam/semantic/segmenter_metadata.h"
#include "pspslam/semantic/semantic_delay.h"
#include "pspslam/session/run_option_table.h"
#include "pspslam/session/run_options.h"
#include "pspslam/session/run_settings.h"
#include "pspslam/session/sequence_runner.h"
#include "pspslam/viewer/live_viewer.h"

namespace pspslam::cli {
namespace {

// Conventional status of a process stopped by SIGINT (128 + 2).
constexpr int kInterruptedExit = 130;
// The whole sequence ran and no frame ever started a map: nothing was tracked.
constexpr int kNeverStartedExit = 3;

// `--blackout FROM:COUNT`: frames FROM .. FROM+COUNT-1 are fed as black images without depth,
// so tracking is really lost (relocalisation tests and demos).
FrameRange parse_blackout(const std::string& value) {
  const size_t colon = value.find(':');
  try {
    if (colon == std::string::npos) throw std::invalid_argument("no colon");
    size_t used_first = 0;
    size_t used_count = 0;
    const std::string first = value.substr(0, colon);
    const std::string count = value.substr(colon + 1);
    FrameRange blackout{std::stoul(first, &used_first), std::stoul(count, &used_count)};
    if (used_first != first.size() || used_count != count.size() || first[0] == '-' ||
        count[0] == '-' || blackout.count == 0)
      throw std::invalid_argument("not two non-negative integers");
    return blackout;
  } catch (const std::logic_error&) {
    throw Error(
        "--blackout expects FROM:COUNT (frame index and a positive number of frames), "
        "got '" +
        value + "'");
  }
}

// The segmentation's classes, for the viewer's label colours; none without semantics.
OverlayClasses overlay_classes(const DynamicOptions& dynamic) {
  if (!uses_semantics(dynamic.mode)) return {};
  const SegmenterMetadata model = load_segmenter_metadata(dynamic.model);
  const std::vector<std::string>& names = dynamic.semantic.dynamic_classes.empty()
                                              ? model.dynamic_classes
                                              : dynamic.semantic.dynamic_classes;
  return {model.classes, class_ids(model.classes, names, model.file.string())};
}

}  // namespace

// The flags of `pspslam run`. Those that shape the System are declared once, with the Python
// keywords, in session/run_option_table.h: registered from that table and gathered into
// `settings` while parsing. The rest are what only a command-line run has: its input, outputs,
// process-wide settings and viewer.
struct RunFlags {
  std::string sequence;
  std::string camera;
  std::string video;  // --video FILE|INDEX (monocular)
  std::string config;
  std::string sensor;  // empty: the config's camera.type
  std::string trajectory_format = "tum";
  std::string out = "pspslam_out";
  size_t max_frames = 0;
  size_t start_frame = 0;
  std::string preload = "auto";
  std::optional<int> priority;  // none: kLiveFramePathNice for live runs, else 0
  int opencv_threads = -1;      // -1: 1 for live runs, else OpenCV's default (all cores)
  std::string save_map;
  std::string blackout;
  std::string export_map;
  std::string export_dense;
  std::string save_masks;
  std::string save_overlays;
  std::string viewer;  // [HOST:]PORT; empty: no viewer
  bool viewer_paused = false;
  int viewer_interval_ms = 250;
  // The table's options: the words typed for each (in table order) and whether it was given.
  std::vector<std::vector<std::string>> option_words =
      std::vector<std::vector<std::string>>(run_option_table().size());
  std::vector<CLI::Option*> option_given = std::vector<CLI::Option*>(run_option_table().size());
  RunSettings settings;  // gathered while parsing
  OccupancyFlags occupancy;
};

// The flags that shape the System, as the library's RunSettings: the table's defaults, each
// flag given, and the checks across flags (Error naming them).
RunSettings gather_settings(const RunFlags& flags) {
  RunSettings settings;
  const std::vector<RunOption>& table = run_option_table();
  for (size_t i = 0; i < table.size(); ++i) {
    if (flags.option_given[i] == nullptr || flags.option_given[i]->count() == 0) continue;
    table[i].set(settings, parse_run_text(table[i], flags.option_words[i]));
  }
  settings.live_camera = !flags.camera.empty();
  check_run_settings(settings, SettingNames{});
  return settings;
}

namespace {

// The run's inputs, outputs and limits.
RunOptions run_options(const RunFlags& flags, const GlobalOptions& global) {
  RunOptions options;
  options.sequence = flags.sequence;
  options.camera = flags.camera;
  options.video = flags.video;
  if (!flags.config.empty()) options.config = flags.config;
  if (!flags.sensor.empty()) options.sensor = parse_sensor_type(flags.sensor, "--sensor");
  options.outputs.kitti_trajectory = flags.trajectory_format == "kitti";
  options.max_frames = flags.max_frames;
  options.start_frame = flags.start_frame;
  options.preload = flags.preload == "on"    ? Preload::on
                    : flags.preload == "off" ? Preload::off
                                             : Preload::automatic;
  if (!flags.blackout.empty()) options.blackout = parse_blackout(flags.blackout);
  options.progress = !global.quiet;
  options.outputs.folder = flags.out;
  options.outputs.save_map = flags.save_map;
  options.outputs.export_map = flags.export_map;
  options.outputs.export_dense = flags.export_dense;
  options.outputs.masks = flags.save_masks;
  options.outputs.overlays = flags.save_overlays;
  options.occupancy = occupancy_options(flags.occupancy, flags.settings);
  // Every output path is checked (and its folder created) before any work.
  prepare_run_outputs(options.outputs);
  prepare_occupancy_outputs(options.occupancy);
  return options;
}

// The viewer binds its address before the model and the sequence load, so a port in use is
// told at once; it outlives the runner, which only points to it.
std::unique_ptr<LiveViewer> start_viewer(const RunFlags& flags, const SystemOptions& system) {
  if (flags.viewer.empty()) return nullptr;
  LiveViewerOptions live;
  live.endpoint = flags.viewer;
  live.web_root = data_dir() / "web";
  live.interval = std::chrono::milliseconds(flags.viewer_interval_ms);
  live.start_paused = flags.viewer_paused;
  live.realtime = flags.settings.realtime;
  live.classes = overlay_classes(system.dynamic);
  live.occupancy = occupancy_options(flags.occupancy, flags.settings).enabled;
  live.title = !flags.video.empty()   ? "video " + flags.video
               : flags.camera.empty() ? flags.sequence
                                      : "camera " + flags.camera;
  if (!flags.sequence.empty() &&
      std::filesystem::is_regular_file(std::filesystem::path(flags.sequence) / "groundtruth.txt"))
    live.ground_truth = std::filesystem::path(flags.sequence) / "groundtruth.txt";
  auto viewer = std::make_unique<LiveViewer>(std::move(live));
  std::cout << "viewer:       " << viewer->url() << "  (live while the run goes"
            << (flags.viewer_paused ? "; held at the first frame until resume or step" : "") << ")"
            << std::endl;
  return viewer;
}

// Said only when the run asked for a raised priority: whether tracking has it (raised now, or
// already as high), or why not.
void report_priority(const ScopedThreadPriority& priority) {
  if (priority.wanted() >= 0) return;
  const int nice = this_thread_nice();
  if (nice <= priority.wanted()) {
    std::cout << "priority:     tracking at nice " << nice
              << " (above busy programs of normal priority)" << std::endl;
  } else {
    std::cout << "priority:     tracking at nice " << nice << ": raising it to "
              << priority.wanted()
              << " needs root or CAP_SYS_NICE, so busy programs beside the run can make it drop "
                 "frames (--priority 0 stops asking)"
              << std::endl;
  }
}

int exit_status(RunOutcome outcome) {
  switch (outcome) {
    case RunOutcome::disconnected:
      return kCameraLostExit;
    case RunOutcome::interrupted:
      return kInterruptedExit;
    case RunOutcome::never_started:
      return kNeverStartedExit;
    case RunOutcome::completed:
      break;
  }
  return 0;
}

}  // namespace

int run_slam(const RunFlags& flags, const GlobalOptions& global) {
  use_single_threaded_blas();  // in every run: its calls are small, its spinning workers are not
  RunOptions options = run_options(flags, global);
  const RunSettings& settings = flags.settings;
  options.system = system_options(settings);
  options.settings = effective_settings(settings, options.system);
  SystemOptions& system = options.system;
  // OpenCV's pool is process-wide: with one thread the network runs on the (lowered) semantic
  // thread alone instead of borrowing workers that compete with tracking at full priority.
  if (flags.opencv_threads >= 0)
    cv::setNumThreads(flags.opencv_threads);
  else if (settings.live())
    cv::setNumThreads(1);

  // A sequence opens in the runner, after the viewer has bound its address; a camera or video
  // opens first, so that a live source can set what the run waits for.
  std::optional<RunInput> live;
  if (flags.sequence.empty()) live = open_run_input(options);
  // A video from a camera index keeps delivering as a camera does (system_options() says so for
  // --camera): without --realtime it waits for local mapping only.
  if (!settings.realtime && live && live->source->live())
    system.back_end_wait = BackEndWait::local_mapping;
  std::unique_ptr<LiveViewer> viewer = start_viewer(flags, system);
  // Raised before the runner starts its threads (a recording's reader, the System's): they inherit
  // it, and the background threads lower theirs from it.
  const ScopedThreadPriority priority(
      flags.priority.value_or(settings.live() ? kLiveFramePathNice : 0));
  report_priority(priority);
  SequenceRunner runner = live ? SequenceRunner(std::move(*live), std::move(options), std::cout)
                               : SequenceRunner(std::move(options), std::cout);
  runner.watch(viewer.get());
  return exit_status(runner.run());
}

namespace {

// What the run reads (a sequence, a camera or a video, with its config and sensor), where it
// writes and how much of it runs. Returns --sequence, which other options need.
CLI::Option* add_input_options(CLI::App* app, const std::shared_ptr<RunFlags>& flags) {
  CLI::Option* sequence = app->add_option("--sequence", flags->sequence, "sequence folder");
  CLI::Option* camera = app->add_option("--camera", flags->camera,
                                        "read a live camera instead of a folder: "
                                        "freenect[:INDEX] (Kinect v1 through libfreenect; "
                                        "config: --config, else config/kinect_v1.yaml)")
                            ->excludes(sequence);
  app->add_option("--video", flags->video,
                  "monocular SLAM on a video file or a camera index (OpenCV VideoCapture; time "
                  "stamps from the file, else frame index / fps); needs --config for the "
                  "intrinsics")
      ->excludes(sequence)
      ->excludes(camera);
  // One input is required; checked while parsing, so nothing is created without one.
  app->callback([flags] {
    if (flags->sequence.empty() && flags->camera.empty() && flags->video.empty())
      throw CLI::RequiredError("--sequence (or --camera or --video)");
    if (!flags->video.empty() && flags->config.empty())
      throw CLI::ValidationError("--video", "needs --config (the camera's intrinsics)");
    if (!flags->video.empty() && !flags->sensor.empty() && flags->sensor != "monocular")
      throw CLI::ValidationError(
          "--video", "is monocular; --sensor " + flags->sensor + " needs a sequence folder");
    try {
      flags->settings = gather_settings(*flags);
    } catch (const Error& e) {
      throw CLI::ValidationError(e.what());
    }
  });
  app->add_option("--config", flags->config,
                  "camera/system config YAML (default: SEQUENCE/config.yaml when it exists, "
                  "else required; presets in config/)");
  app->add_option("--sensor", flags->sensor,
                  "rgbd | stereo | monocular: overrides the config's camera.type (monocular reads "
                  "the colour images of any RGB-D folder and ignores depth)");
  app->add_option("--trajectory-format", flags->trajectory_format,
                  "tum, or kitti: also write OUT/trajectory_kitti.txt and "
                  "trajectory_refined_kitti.txt (3x4 row-major camera-to-world per tracked frame)")
      ->check(CLI::IsMember({"tum", "kitti"}))
      ->capture_default_str();
  app->add_option("--out", flags->out, "output folder")->capture_default_str();
  app->add_option("--max-frames", flags->max_frames, "process at most this many frames (0 = all)")
      ->check(in_range(size_t{0}, size_t{1000000000}))
      ->capture_default_str();
  app->add_option("--start-frame", flags->start_frame,
                  "start a sequence at this frame (0 = the first), skipping those before it; "
                  "frames keep their sequence positions in the outputs")
      ->check(in_range(size_t{0}, size_t{1000000000}))
      ->needs(sequence)
      ->capture_default_str();
  return sequence;
}

// The options of the table (session/run_option_table.h), shared with the Python module: each
// registered with its checks, its words kept for gather_settings().
void add_table_options(CLI::App* app, RunFlags& flags, CLI::Option* sequence) {
  const std::vector<RunOption>& table = run_option_table();
  for (size_t i = 0; i < table.size(); ++i) {
    const RunOption& option = table[i];
    if (option.flag.empty()) continue;  // set otherwise (live: --camera)
    if (option.kind == RunOptionKind::flag || option.kind == RunOptionKind::negated_flag) {
      flags.option_given[i] = app->add_flag(option.flag, option.help);
      continue;
    }
    CLI::Option* added = app->add_option(option.flag, flags.option_words[i], option.help);
    added->expected(option.kind == RunOptionKind::real_pair ? 2 : 1);
    added->check(
        CLI::Validator([&option](std::string& word) { return run_text_problem(option, {word}); },
                       option.value_name));
    if (const std::string shown = option.value_text(RunSettings{}); !shown.empty())
      added->default_str(shown);
    flags.option_given[i] = added;
  }
  // A folder of masks matches a sequence's images by name.
  flags
      .option_given[static_cast<size_t>(find_run_option_by_flag("--semantic-masks") - table.data())]
      ->needs(sequence);
}

// Real-time runs: how frames are fed and how the threads share the cores.
void add_live_options(CLI::App* app, RunFlags& flags) {
  app->add_option("--preload", flags.preload,
                  "with --realtime on a recording: on = decode every frame before the replay "
                  "starts, so that no image decoding shares the cores with the run (a camera "
                  "delivers decoded frames; refused above 8 GiB), off = decode each frame ahead "
                  "on a reader thread, auto = on up to 2 GiB of decoded frames")
      ->check(CLI::IsMember({"auto", "on", "off"}))
      ->capture_default_str();
  app->add_option("--priority", flags.priority,
                  "nice value asked for tracking and the threads it starts, so that it keeps up "
                  "with the camera beside busy programs (needs root or CAP_SYS_NICE; without, "
                  "the run says so and goes on). Default: " +
                      std::to_string(kLiveFramePathNice) +
                      " with --realtime or --camera, 0 (unchanged) otherwise")
      ->check(in_range(-20, 0));
  app->add_option("--opencv-threads", flags.opencv_threads,
                  "OpenCV worker threads (network, image operations; 0 = OpenCV's default, all "
                  "cores). Default: 1 with --realtime or --camera, so that the network runs on "
                  "the lowered semantic thread alone; OpenCV's default otherwise")
      ->check(in_range(0, 256));
}

// The map file written at the end, and forced tracking loss.
void add_map_options(CLI::App* app, RunFlags& flags) {
  app->add_option("--save-map", flags.save_map,
                  "write the final map to this file (binary, see docs/place_recognition.md)");
  app->add_option("--blackout", flags.blackout,
                  "FROM:COUNT: feed frames FROM..FROM+COUNT-1 as black images without depth "
                  "(tracking is lost for real; tests relocalisation)")
      ->check(CLI::Validator(
          [](std::string& value) {
            try {
              parse_blackout(value);
              return std::string();
            } catch (const Error& e) {
              return std::string(e.what());
            }
          },
          "FROM:COUNT"));
}

// Optional outputs beside the trajectory files: point clouds, masks and overlays.
void add_output_options(CLI::App* app, RunFlags& flags) {
  app->add_option("--export-map", flags.export_map,
                  "write the final static map points as a PLY point cloud (dynamic points never "
                  "enter the map or are culled from it)");
  app->add_option("--export-dense", flags.export_dense,
                  "also write a dense PLY cloud back-projected from the keyframes' depth at their "
                  "final poses, dynamic pixels left out (1 cm voxels, every 4th pixel)");
  app->add_option("--save-masks", flags.save_masks,
                  "write each processed frame's final dynamic mask (semantic + geometry) into "
                  "this folder: 8-bit PNG, 255 = dynamic, named after the colour image "
                  "(rgb/1548339828.32144.png -> DIR/1548339828.32144.png)");
  app->add_option("--save-overlays", flags.save_overlays,
                  "write a picture per processed frame into this folder: the semantic overlay with "
                  "every keypoint marked by its fate (tracked / kept unmatched / dropped by the "
                  "semantic mask / dropped by the geometry test) and a legend; costs a second ORB "
                  "extraction per frame");
}

// The live viewer in the browser.
void add_viewer_options(CLI::App* app, RunFlags& flags) {
  CLI::Option* viewer =
      app->add_option("--viewer", flags.viewer,
                      "[HOST:]PORT: show the run live in the browser (frame, keypoint fates, "
                      "masks, map, timing; host 127.0.0.1 unless given; port 0: any free one)");
  app->add_flag("--viewer-paused", flags.viewer_paused,
                "hold the run after its first frame until the page says resume or step "
                "(deterministic runs)")
      ->needs(viewer);
  app->add_option("--viewer-interval", flags.viewer_interval_ms,
                  "milliseconds between the frames the viewer shows (the run never waits for it)")
      ->check(in_range(10, 60000))
      ->needs(viewer)
      ->capture_default_str();
}

}  // namespace

Command add_run_command(CLI::App& root) {
  CLI::App* app = root.add_subcommand(
      "run",
      "run SLAM on an RGB-D sequence and write the trajectory.\n"
      "Reads a sequence in TUM layout (rgb.txt, depth.txt or associations.txt, optional "
      "groundtruth.txt)\nand writes OUT/trajectory_refined.txt (the file to evaluate), "
      "OUT/trajectory.txt (every frame as tracked),\nOUT/lost_frames.txt, OUT/keyframes.txt, "
      "OUT/timing.csv, "
      "OUT/stats.json and OUT/run_config.yaml (the config used). With ground truth, prints ATE.");
  auto flags = std::make_shared<RunFlags>();
  CLI::Option* sequence = add_input_options(app, flags);
  add_table_options(app, *flags, sequence);
  add_live_options(app, *flags);
  add_map_options(app, *flags);
  add_output_options(app, *flags);
  add_occupancy_options(app, flags->occupancy);
  add_viewer_options(app, *flags);
  return {app, [flags](const GlobalOptions& global) { return run_slam(*flags, global); }};
}

}  // namespace pspslam::cli
