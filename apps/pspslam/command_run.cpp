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
//   trajectory_refined.txt  the final trajectory, written at the end: the frames of
//                    trajectory.txt moved with the BA-refined keyframes around them in time
//   timing.csv       per frame: extraction / tracking / local BA milliseconds, state, and the
//                    dynamic-scene stages (mask age, geometry time, masked keypoints)
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
#include "pspslam/config/config.h"
#include "pspslam/core/error.h"
#include "pspslam/core/shared_paths.h"
#include "pspslam/core/thread_priority.h"
#include "pspslam/semantic/segmenter.h"
#include "pspslam/semantic/segmenter_metadata.h"
#include "pspslam/semantic/semantic_delay.h"
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
  bool no_local_mapping = false;
  std::string dynamic = "auto";
  std::string model;           // empty: the shipped model
  std::string semantic_masks;  // empty: the network segments the frames
  bool realtime = false;
  std::string preload = "auto";
  int background_nice = -1;     // -1: kLiveBackgroundNice for live runs, else 0
  std::optional<int> priority;  // none: kLiveFramePathNice for live runs, else 0
  int opencv_threads = -1;      // -1: 1 for live runs, else OpenCV's default (all cores)
  int mask_margin = 5;
  int segment_every = 1;
  std::string semantic_pace = "off";
  std::string smaller_model;  // empty: the shipped smaller input when --model is the shipped one
  std::string stale_masks = "homography";
  int stale_mask_growth = MaskPropagationParams{}.max_growth_px;
  std::string mover_guard = "off";
  std::string stale_geometry = "on";
  std::string late_mask_culling = "on";
  std::string judged_points_first = "on";
  std::string semantic_delay;  // empty: none (fault injection)
  std::uint32_t semantic_delay_seed = 1;
  double keyframe_ratio = KeyFramePolicyOptions{}.tracked_ratio_to_reference;
  bool due_keyframes = false;
  int local_ba_keyframes = -1;  // -1: kLiveLocalBaKeyframes for live runs, else 0 (all)
  double ba_tracking_factors = 0.0;
  int local_ba_fixed_keyframes = 0;
  std::vector<double> motion_prior;  // {σ_t mm, σ_r degrees}; empty: none
  std::string vocabulary;            // empty: the shipped vocabulary
  bool no_relocalization = false;
  double new_map_after = -1.0;  // -1: kNewMapAfterSeconds, kLiveNewMapAfterSeconds for live runs
  std::string loop_closing = "auto";
  std::string save_map;
  std::string load_map;
  bool localization = false;
  std::string blackout;
  int cull_hits = 3;
  std::string export_map;
  std::string export_dense;
  std::string save_masks;
  std::string save_overlays;
  std::string viewer;  // [HOST:]PORT; empty: no viewer
  bool viewer_paused = false;
  int viewer_interval_ms = 250;
};

// A path the user typed (relative to the current folder); empty: the run's default.
std::optional<std::filesystem::path> typed_path(const std::string& typed) {
  if (typed.empty()) return std::nullopt;
  return std::filesystem::path(typed);
}

// The flags that shape the System, as the library's RunSettings.
RunSettings run_settings(const RunFlags& flags) {
  RunSettings settings;
  settings.mode = flags.dynamic;
  settings.model = typed_path(flags.model);
  settings.vocabulary = typed_path(flags.vocabulary);
  settings.semantic_masks = typed_path(flags.semantic_masks);
  settings.load_map = typed_path(flags.load_map);
  settings.localization = flags.localization;
  settings.realtime = flags.realtime;
  settings.live_camera = !flags.camera.empty();
  settings.local_mapping = !flags.no_local_mapping;
  settings.relocalization = !flags.no_relocalization;
  if (flags.new_map_after >= 0.0) settings.new_map_after = flags.new_map_after;
  settings.loop_closing = flags.loop_closing;
  settings.mask_margin = flags.mask_margin;
  settings.segment_every = flags.segment_every;
  settings.cull_hits = flags.cull_hits;
  settings.keyframe_ratio = flags.keyframe_ratio;
  settings.due_keyframes = flags.due_keyframes;
  if (flags.local_ba_keyframes >= 0) settings.local_ba_keyframes = flags.local_ba_keyframes;
  settings.ba_tracking_factors = flags.ba_tracking_factors;
  settings.local_ba_fixed_keyframes = flags.local_ba_fixed_keyframes;
  if (flags.background_nice >= 0) settings.background_nice = flags.background_nice;
  if (flags.motion_prior.size() == 2)
    settings.motion_prior = std::pair(flags.motion_prior[0], flags.motion_prior[1]);
  return settings;
}

// The flags only `pspslam run` has (semantic pacing, stale masks, mover guard, fault injection);
// the Python module keeps their defaults.
void set_cli_only_options(const RunFlags& flags, SystemOptions& system) {
  DynamicOptions& dynamic = system.dynamic;
  dynamic.keep_pace = flags.semantic_pace == "on";
  const std::filesystem::path shipped_smaller = data_dir() / "models/pspnet/pspnet_288x192.yaml";
  if (!flags.smaller_model.empty())
    dynamic.smaller_model = flags.smaller_model;
  else if (flags.model.empty() && std::filesystem::is_regular_file(shipped_smaller))
    dynamic.smaller_model = shipped_smaller;
  system.tracker.mover_guard.enabled = flags.mover_guard == "on";
  dynamic.tighten_geometry = flags.stale_geometry == "on";
  dynamic.cull_with_late_masks = flags.late_mask_culling == "on";
  system.tracker.judged_points_first = flags.judged_points_first == "on";
  dynamic.propagation.max_growth_px = flags.stale_mask_growth;
  dynamic.stale_masks =
      flags.stale_masks == "flow" ? StaleMaskPolicy::flow : StaleMaskPolicy::homography;
  if (!flags.semantic_delay.empty()) {
    dynamic.semantic.injected_delay =
        parse_semantic_delay(flags.semantic_delay, "--semantic-delay-ms");
    dynamic.semantic.injected_delay.seed = flags.semantic_delay_seed;
  }
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
  // Every output path is checked (and its folder created) before any work.
  prepare_run_outputs(options.outputs);
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
  live.realtime = flags.realtime;
  live.classes = overlay_classes(system.dynamic);
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
  const RunSettings settings = run_settings(flags);
  options.system = system_options(settings);
  SystemOptions& system = options.system;
  // OpenCV's pool is process-wide: with one thread the network runs on the (lowered) semantic
  // thread alone instead of borrowing workers that compete with tracking at full priority.
  if (flags.opencv_threads >= 0)
    cv::setNumThreads(flags.opencv_threads);
  else if (settings.live())
    cv::setNumThreads(1);
  set_cli_only_options(flags, system);

  // A sequence opens in the runner, after the viewer has bound its address; a camera or video
  // opens first, so that a live source can set what the run waits for.
  std::optional<RunInput> live;
  if (flags.sequence.empty()) live = open_run_input(options);
  // A camera keeps delivering while the run waits: a loop's global BA (seconds) would drop a
  // second of frames, so a live run without --realtime waits for local mapping only.
  if (!flags.realtime && live && live->source->live())
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
  app->add_flag("--no-local-mapping", flags->no_local_mapping,
                "track only: keyframes enter the map but are never refined (debugging)");
  return sequence;
}

// How dynamic content is found.
void add_dynamic_options(CLI::App* app, RunFlags& flags) {
  app->add_option("--dynamic", flags.dynamic,
                  "dynamic-scene mode: off | semantic | geometry | full | exhaustive | auto "
                  "(auto = full when the segmentation model loads, else geometry)")
      ->check(CLI::IsMember({"off", "semantic", "geometry", "full", "exhaustive", "auto"}))
      ->capture_default_str();
  app->add_option("--model", flags.model,
                  "segmentation metadata YAML (default: the shipped models/pspnet/pspnet.yaml)");
}

// Real-time runs: how frames are fed and how the threads share the cores.
void add_live_options(CLI::App* app, RunFlags& flags) {
  app->add_flag("--realtime", flags.realtime,
                "feed frames at the sequence's rate (late frames are dropped) and never wait for "
                "segmentation or the back end: use the newest mask, warped into the frame "
                "(default: deterministic, each frame waits for its mask and for local mapping, "
                "loop closing and any global BA to finish the previous keyframe; a camera waits "
                "for local mapping only)");
  app->add_option("--preload", flags.preload,
                  "with --realtime on a recording: on = decode every frame before the replay "
                  "starts, so that no image decoding shares the cores with the run (a camera "
                  "delivers decoded frames; refused above 8 GiB), off = decode each frame ahead "
                  "on a reader thread, auto = on up to 2 GiB of decoded frames")
      ->check(CLI::IsMember({"auto", "on", "off"}))
      ->capture_default_str();
  app->add_option("--background-nice", flags.background_nice,
                  "scheduling priority given up by the semantic, local mapping and loop closing "
                  "threads below tracking's (nice increment, 0-19) so that tracking gets a core "
                  "when a frame arrives (default: " +
                      std::to_string(kLiveBackgroundNice) +
                      " with --realtime or --camera, 0 otherwise)")
      ->check(in_range(0, 19));
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

// How often the network runs and how the frames between use an older mask.
void add_stale_mask_options(CLI::App* app, RunFlags& flags) {
  app->add_option("--segment-every", flags.segment_every,
                  "segment every n-th frame; the frames between use the newest mask, moved "
                  "with the camera by the frame-to-frame homographies")
      ->check(in_range(1, 30))
      ->capture_default_str();
  app->add_option("--semantic-pace", flags.semantic_pace,
                  "with --realtime: when segmentation falls behind the camera, step down by "
                  "itself to the smaller network input (--smaller-model), then to segmenting "
                  "every 2nd or 3rd frame, and back up when there is room (off: one network on "
                  "every frame it can take)")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str();
  app->add_option("--smaller-model", flags.smaller_model,
                  "the smaller segmentation model --semantic-pace steps down to (default: the "
                  "shipped models/pspnet/pspnet_288x192.yaml when --model is the shipped one, "
                  "else none: only sparser frames)")
      ->check(CLI::ExistingFile);
  app->add_option("--stale-masks", flags.stale_masks,
                  "with --realtime, how an older mask is brought into the frame: flow = each "
                  "person moves by the optical flow inside it and the mask grows with its age, "
                  "and keypoints near a mask more than 2 frames old get the geometry test "
                  "(experimental: it can leave a crowd too few static keypoints); homography = "
                  "moved with the camera only")
      ->check(CLI::IsMember({"flow", "homography"}))
      ->capture_default_str();
  app->add_option("--stale-mask-growth", flags.stale_mask_growth,
                  "with --stale-masks flow: the most pixels a moved mask grows by for its age")
      ->check(in_range(0, 200))
      ->capture_default_str();
  app->add_option("--stale-geometry", flags.stale_geometry,
                  "with --realtime and --stale-masks flow: while the mask is more than 2 frames "
                  "old, every keypoint in a band around it gets the multi-view geometry test")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str();
  app->add_option("--late-mask-culling", flags.late_mask_culling,
                  "with --realtime: a mask that arrives after its frame was tracked still judges "
                  "that frame; map points the frame saw on its people count towards their "
                  "culling, and a mask more than 2 frames old culls nothing (off: the newest "
                  "mask culls, however old)")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str();
  app->add_option("--judged-points-first", flags.judged_points_first,
                  "with --realtime and --late-mask-culling on: while the mask is more than 2 "
                  "frames old, a frame's pose is solved on the map points an exact mask has "
                  "judged first, and newer points count only where they agree with it (off: "
                  "every match alike, which lets a crowd the stale mask missed carry the pose)")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str();
  app->add_option("--mover-guard", flags.mover_guard,
                  "experimental: when a frame's inliers drop and its pose jumps off the "
                  "constant-velocity prediction (tracking following a crowd), hold the "
                  "prediction for up to 3 frames")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str();
}

// Where the semantic masks come from (the network, slowed down on purpose, or a folder) and
// how far they are grown.
void add_mask_source_options(CLI::App* app, RunFlags& flags, CLI::Option* sequence) {
  CLI::Option* semantic_delay =
      app->add_option("--semantic-delay-ms", flags.semantic_delay,
                      "fault injection: MS or random:MIN:MAX milliseconds of extra wait after each "
                      "segmentation, as if the network were that much slower (reproduces a "
                      "network that falls behind the camera)")
          ->check(CLI::Validator(
              [](std::string& value) {
                try {
                  parse_semantic_delay(value, "--semantic-delay-ms");
                  return std::string();
                } catch (const Error& e) {
                  return std::string(e.what());
                }
              },
              "MS|random:MIN:MAX"));
  app->add_option("--semantic-delay-seed", flags.semantic_delay_seed,
                  "seed of the random:MIN:MAX delays (the same seed draws the same delays)")
      ->needs(semantic_delay)
      ->capture_default_str();
  app->add_option("--semantic-masks", flags.semantic_masks,
                  "read each frame's semantic mask from this folder instead of running the "
                  "network: DIR/<colour image name>.png, 8-bit, non-zero = dynamic (what "
                  "--save-masks writes; a synth sequence's mask/ folder); grown by --mask-margin")
      ->check(CLI::ExistingDirectory)
      ->needs(sequence);
  app->add_option("--mask-margin", flags.mask_margin,
                  "dilation of the semantic dynamic mask (pixels)")
      ->check(in_range(0, 100))
      ->capture_default_str();
}

// When a frame becomes a keyframe, how far local BA reaches and how a frame's pose is
// optimised.
void add_keyframe_options(CLI::App* app, RunFlags& flags) {
  app->add_option("--keyframe-ratio", flags.keyframe_ratio,
                  "a frame becomes a keyframe when it tracks fewer than this share of its "
                  "reference keyframe's points (ORB-SLAM2: 0.75; higher = denser keyframes)")
      ->check(in_range(0.01, 1.0))
      ->capture_default_str();
  app->add_option("--local-ba-keyframes", flags.local_ba_keyframes,
                  "local BA optimises the new keyframe and at most this many of its best "
                  "covisible keyframes; 0 = all of them, as ORB-SLAM2 (default: " +
                      std::to_string(kLiveLocalBaKeyframes) +
                      " with --realtime or --camera, so that local BA keeps up on two cores; 0 "
                      "otherwise)")
      ->check(in_range(0, 1000));
  app->add_option("--local-ba-fixed-keyframes", flags.local_ba_fixed_keyframes,
                  "of the keyframes held fixed around the local BA window (those that see its "
                  "points), keep the ones that see the most of them; 0 = all, as ORB-SLAM2 "
                  "(bounds local BA where a revisited room has many)")
      ->check(in_range(0, 1000))
      ->capture_default_str();
  app->add_option("--ba-tracking-factors", flags.ba_tracking_factors,
                  "WEIGHT: local BA also keeps each keyframe's pose relative to the keyframe "
                  "before it as tracking measured it, weighted by WEIGHT times the information "
                  "of its pose-only optimisation (0 = off, ORB-SLAM2's BA)")
      ->check(in_range(0.0, 1e6))
      ->capture_default_str();
  app->add_flag("--due-keyframes", flags.due_keyframes,
                "also make a keyframe once a second has passed since the last one, whatever "
                "--keyframe-ratio says (keeps keyframes dense on a camera that keeps exploring; "
                "off by default: docs/decisions/due-keyframes.md)");
  app->add_option("--motion-prior", flags.motion_prior,
                  "MM DEG: optimise each frame tracked with the motion model with its "
                  "constant-velocity prediction as a prior of these σs (translation mm, rotation "
                  "degrees; default: no prior; it lowers the jitter, not the ATE)")
      ->expected(2)
      ->check(in_range(1e-3, 1e3));
}

// The map: vocabulary, relocalisation, loop closing, saved maps, forced tracking loss and
// culling of dynamic points.
void add_map_options(CLI::App* app, RunFlags& flags) {
  app->add_option("--vocabulary", flags.vocabulary,
                  "ORB bag-of-words vocabulary for relocalisation and loop closing (default: the "
                  "shipped models/vocabulary/orb_k10_l5.pspvoc)");
  app->add_flag("--no-relocalization", flags.no_relocalization,
                "do not relocalise when tracking is lost (and do not load the vocabulary)");
  app->add_option("--new-map-after", flags.new_map_after,
                  "SECONDS lost, with relocalisation failing in every map, before tracking starts "
                  "a new map in the atlas; loop closing merges it when a place is recognised "
                  "across the two (0: never; the run stays lost until relocalised; default: " +
                      fmt::format("{:g} s, {:g} s for live runs", kNewMapAfterSeconds,
                                  kLiveNewMapAfterSeconds) +
                      ")")
      ->check(in_range(0.0, 3600.0));
  app->add_option("--loop-closing", flags.loop_closing,
                  "loop closing thread (detection, essential-graph correction, global BA); auto = "
                  "on when the vocabulary file exists")
      ->check(CLI::IsMember({"on", "off", "auto"}))
      ->capture_default_str();
  app->add_option("--save-map", flags.save_map,
                  "write the final map to this file (binary, see docs/place_recognition.md)");
  CLI::Option* load_map =
      app->add_option("--load-map", flags.load_map,
                      "start from this saved map: the first frame is relocalised in it")
          ->check(CLI::ExistingFile);
  app->add_flag("--localization", flags.localization,
                "localisation only (needs --load-map): track in the map, never add to it")
      ->needs(load_map);
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
  app->add_option("--cull-hits", flags.cull_hits,
                  "erase a map point after it lay on dynamic pixels in this many frames")
      ->check(in_range(1, 1000))
      ->capture_default_str();
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
      "groundtruth.txt)\nand writes OUT/trajectory.txt (every tracked frame), "
      "OUT/trajectory_refined.txt, OUT/lost_frames.txt,\nOUT/keyframes.txt, OUT/timing.csv, "
      "OUT/stats.json and OUT/run_config.yaml (the config used). With ground truth, prints ATE.");
  auto flags = std::make_shared<RunFlags>();
  CLI::Option* sequence = add_input_options(app, flags);
  add_dynamic_options(app, *flags);
  add_live_options(app, *flags);
  add_stale_mask_options(app, *flags);
  add_mask_source_options(app, *flags, sequence);
  add_keyframe_options(app, *flags);
  add_map_options(app, *flags);
  add_output_options(app, *flags);
  add_viewer_options(app, *flags);
  return {app, [flags](const GlobalOptions& global) { return run_slam(*flags, global); }};
}

}  // namespace pspslam::cli
