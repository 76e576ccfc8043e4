// `pspslam run`: SLAM on an RGB-D sequence. Writes into OUT/
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
#include <spdlog/spdlog.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <tuple>
#include <utility>
#include <vector>

#include "commands.h"
#include "flag_checks.h"
#include "pspslam/core/error.h"
#include "pspslam/core/interrupt.h"
#include "pspslam/core/output_paths.h"
#include "pspslam/core/progress.h"
#include "pspslam/core/shared_paths.h"
#include "pspslam/eval/ate.h"
#include "pspslam/io/sequence_setup.h"
#include "pspslam/io/trajectory_io.h"
#include "pspslam/map/map.h"
#include "pspslam/place/place_recognition.h"
#include "pspslam/semantic/segmenter_metadata.h"
#include "pspslam/system/map_export.h"
#include "pspslam/system/system.h"

namespace pspslam::cli {
namespace {

// Conventional status of a process stopped by SIGINT (128 + 2).
constexpr int kInterruptedExit = 130;
// The whole sequence ran and no frame ever started a map: nothing was tracked.
constexpr int kNeverStartedExit = 3;

// Watches the frames before the first map. A sequence without depth readings never starts; the
// user is told so (once, after `warn_after` such frames) with the best frame's depth count, not
// left with an empty trajectory and no reason.
class StartWatch {
 public:
  explicit StartWatch(size_t warn_after) : warn_after_(warn_after) {}

  void update(const TrackResult& result) {
    if (result.state != TrackingState::kNotInitialized) started_ = true;
    if (started_ || result.keypoints_with_depth_needed == 0) return;
    best_ = std::max(best_, result.keypoints_with_depth);
    needed_ = result.keypoints_with_depth_needed;
    if (++waiting_ == warn_after_) spdlog::warn("{}", reason());
  }
  bool never_started() const { return !started_ && waiting_ > 0; }
  std::string reason() const {
    return "no map after " + std::to_string(waiting_) + " frames: the best frame had " +
           std::to_string(best_) + " keypoints with a depth reading, " + std::to_string(needed_) +
           " are needed to start one (are the depth images listed in depth.txt empty?)";
  }

 private:
  size_t warn_after_;
  size_t waiting_ = 0;
  int best_ = 0;
  int needed_ = 0;
  bool started_ = false;
};

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  return values[mid];
}

// {median, mean, p95} of one module's per-frame milliseconds.
struct TimingSummary {
  double median = 0.0;
  double mean = 0.0;
  double p95 = 0.0;
  size_t count = 0;
};

TimingSummary summarize(std::vector<double> values) {
  TimingSummary summary;
  summary.count = values.size();
  if (values.empty()) return summary;
  std::sort(values.begin(), values.end());
  double sum = 0.0;
  for (const double v : values) sum += v;
  summary.mean = sum / static_cast<double>(values.size());
  summary.median = values[values.size() / 2];
  summary.p95 = values[std::min(values.size() - 1,
                                static_cast<size_t>(0.95 * static_cast<double>(values.size())))];
  return summary;
}

nlohmann::ordered_json to_json(const TimingSummary& t) {
  return {{"median", t.median}, {"mean", t.mean}, {"p95", t.p95}, {"count", t.count}};
}

// Picks the dynamic mode. `auto` = full when the segmentation model can be loaded, else geometry
// with a warning that says which model is missing and how to get it; an explicitly requested
// semantic mode with a missing model is an error.
DynamicMode choose_mode(const std::string& flag_value, const std::filesystem::path& model,
                        bool explicit_model) {
  const bool automatic = flag_value == "auto";
  const DynamicMode wanted =
      automatic ? DynamicMode::full : parse_dynamic_mode(flag_value, "--dynamic");
  if (!uses_semantics(wanted)) return wanted;
  try {
    load_segmenter_metadata(model);
    return wanted;
  } catch (const Error& e) {
    const std::string how =
        "segmentation model not usable: " + std::string(e.what()) +
        "\n  get it: train/export our PSPNet with tools/pspnet (models/pspnet/pspnet.yaml + "
        ".onnx),\n  or pass a teacher, e.g. --model models/teachers/deeplabv3_mnv2_pascal.yaml "
        "(ONNX in ../shared/models)";
    if (!automatic || explicit_model) throw Error("--dynamic " + flag_value + ": " + how);
    spdlog::warn("{}\n  falling back to --dynamic geometry", how);
    return DynamicMode::geometry;
  }
}

// `--loop-closing on|off|auto`: auto = on when the vocabulary file exists.
bool parse_loop_closing(const std::string& value, const std::filesystem::path& vocabulary) {
  return value == "on" || (value == "auto" && std::filesystem::exists(vocabulary));
}

void print_loop_stats(const MappingStats& mapping) {
  std::printf(
      "loops:        %zu closed (last moved its keyframe %.3f m), %zu candidates rejected by "
      "geometry; global BA %zu applied, %zu aborted (last %.2f s)\n",
      mapping.loops_closed, mapping.last_loop_correction_m, mapping.loop_candidates_rejected,
      mapping.global_ba_applied, mapping.global_ba_aborted, mapping.last_global_ba_seconds);
}

// `--blackout FROM:COUNT`: frames FROM .. FROM+COUNT-1 are fed as black images without depth,
// so tracking is really lost (relocalisation tests and demos).
struct Blackout {
  size_t first = 0;
  size_t count = 0;
  size_t end() const { return first + count; }
  bool covers(size_t index) const { return index >= first && index < end(); }
};

Blackout parse_blackout(const std::string& value) {
  const size_t colon = value.find(':');
  try {
    if (colon == std::string::npos) throw std::invalid_argument("no colon");
    size_t used_first = 0;
    size_t used_count = 0;
    const std::string first = value.substr(0, colon);
    const std::string count = value.substr(colon + 1);
    Blackout blackout{std::stoul(first, &used_first), std::stoul(count, &used_count)};
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

std::ofstream open_output(const std::filesystem::path& file) {
  std::ofstream stream(file);
  if (!stream) throw Error(file.string() + ": cannot write output file");
  return stream;
}

// --export-map / --export-dense, after shutdown (local mapping has refined the poses).
void write_map_exports(const std::string& map_file, const std::string& dense_file,
                       const MapExporter& exporter, const Map& map) {
  const std::vector<std::string> comment = {"pspslam static map, world frame (metres)"};
  if (!map_file.empty()) {
    const std::vector<ColoredPoint> cloud = exporter.map_points(map);
    write_point_cloud_ply(map_file, cloud, comment);
    std::cout << "map export:   " << map_file << " (" << cloud.size() << " points)\n";
  }
  if (!dense_file.empty()) {
    const std::vector<ColoredPoint> cloud = exporter.dense_cloud(map, DenseCloudOptions{});
    write_point_cloud_ply(dense_file, cloud, comment);
    std::cout << "map export:   " << dense_file << " (" << cloud.size() << " points, from "
              << exporter.remembered_keyframes() << " keyframe images)\n";
  }
}

}  // namespace

struct RunFlags {
  std::string sequence;
  std::string config;
  std::string out = "pspslam_out";
  size_t max_frames = 0;
  bool no_local_mapping = false;
  std::string dynamic = "auto";
  std::string model;  // empty: the shipped model
  bool realtime = false;
  int mask_margin = 5;
  double keyframe_ratio = KeyFramePolicyOptions{}.tracked_ratio_to_reference;
  std::string vocabulary;  // empty: the shipped vocabulary
  bool no_relocalization = false;
  std::string loop_closing = "auto";
  std::string save_map;
  std::string load_map;
  bool localization = false;
  std::string blackout;
  int cull_hits = 3;
  std::string export_map;
  std::string export_dense;
};

// A path the user typed is relative to the current folder; only the built-in defaults are found
// next to the program.
std::filesystem::path user_or_default(const std::string& typed,
                                      const std::filesystem::path& shipped) {
  return typed.empty() ? shipped : std::filesystem::path(typed);
}

int run_slam(const RunFlags& flags, const GlobalOptions& global) {
  const size_t max_frames_flag = flags.max_frames;
  // Assigned, not built by a conditional expression: GCC 12 then reports a false
  // "maybe-uninitialized" on blackout->end() under -Werror.
  std::optional<Blackout> blackout;
  if (!flags.blackout.empty()) blackout = parse_blackout(flags.blackout);

  // Every output path is checked (and its folder created) before any work, so a run never
  // computes for minutes and then fails to write.
  const std::filesystem::path out_dir = flags.out;
  prepare_output_folder(out_dir, "--out");
  const std::pair<const char*, const std::string*> output_files[] = {
      {"--save-map", &flags.save_map},
      {"--export-map", &flags.export_map},
      {"--export-dense", &flags.export_dense}};
  for (const auto& [flag, file] : output_files) {
    if (!file->empty()) prepare_output_file(*file, flag);
  }

  SystemOptions system_options;
  DynamicOptions& dynamic = system_options.dynamic;
  dynamic.model = user_or_default(flags.model, data_dir() / "models/pspnet/pspnet.yaml");
  dynamic.mode = choose_mode(flags.dynamic, dynamic.model, !flags.model.empty());

  const std::optional<std::filesystem::path> config =
      !flags.config.empty() ? std::optional<std::filesystem::path>(flags.config) : std::nullopt;
  const SequenceSetup setup = open_sequence_with_config(
      flags.sequence, config, spdlog::should_log(spdlog::level::warn) ? &std::cerr : nullptr);
  const RgbdSequence& sequence = setup.sequence;
  const PinholeCamera& camera = setup.config.camera.pinhole;
  const size_t frames =
      max_frames_flag == 0 ? sequence.size() : std::min(sequence.size(), max_frames_flag);

  TrajectoryWriter trajectory(out_dir / "trajectory.txt");
  std::ofstream lost = open_output(out_dir / "lost_frames.txt");
  lost << "# frames without a pose (tracking not initialised or lost): index timestamp state\n";
  std::ofstream timing = open_output(out_dir / "timing.csv");
  timing << "index,timestamp,state,method,keypoints,inliers,keyframe,extraction_ms,tracking_ms,"
            "local_ba_ms,mapping_queue,extraction_cpu_ms,tracking_cpu_ms,flow_ms,semantic_wait_ms,"
            "mask_age,geometry_ms,tested,dynamic,masked_keypoints,culled_points\n";
  std::cout << describe_sequence(setup);

  system_options.local_mapping = !flags.no_local_mapping;
  system_options.synchronous_local_mapping = !flags.realtime;
  system_options.tracker.keyframes.tracked_ratio_to_reference = flags.keyframe_ratio;
  dynamic.realtime = flags.realtime;
  dynamic.semantic.mask_dilation_px = flags.mask_margin;
  dynamic.culling.min_dynamic_hits = flags.cull_hits;
  std::cout << "dynamic:      " << to_string(dynamic.mode)
            << (uses_semantics(dynamic.mode) ? " (model " + dynamic.model.string() + ")" : "")
            << (dynamic.realtime ? ", real-time feed" : ", deterministic (waits for each mask)")
            << "\n";
  system_options.place.relocalization = !flags.no_relocalization;
  if (!flags.load_map.empty()) {
    system_options.map_file = flags.load_map;
    system_options.localization_only = flags.localization;
    std::cout << "map:          " << system_options.map_file.string()
              << (system_options.localization_only ? " (localisation only)" : " (extended)")
              << "\n";
  }
  system_options.place.vocabulary = user_or_default(flags.vocabulary, default_vocabulary_path());
  // Localisation never changes the map, so it never closes loops (System turns it off too).
  system_options.place.loop_closing =
      !system_options.localization_only &&
      parse_loop_closing(flags.loop_closing, system_options.place.vocabulary);
  std::cout << "loop closing: " << (system_options.place.loop_closing ? "on" : "off") << "\n";
  System system(setup.config, system_options);
  std::optional<MapExporter> exporter;
  if (!flags.export_map.empty() || !flags.export_dense.empty()) exporter.emplace(camera);
  InterruptGuard interrupt_guard;
  ProgressBar progress("slam", frames, std::cerr, !global.quiet, flags.realtime);
  std::vector<double> extraction_ms;
  std::vector<double> tracking_ms;
  std::vector<double> tracking_cpu_ms;
  std::vector<double> semantic_ms;  // inference time of each mask used (once per mask)
  std::vector<double> semantic_wait_ms;
  std::vector<double> geometry_ms;
  std::vector<double> geometry_search_ms;
  std::vector<double> flow_ms;
  std::vector<double> local_mapping_ms;  // one entry per local BA
  std::vector<double> mask_age_frames;
  std::vector<double> mask_latency_ms;
  size_t tested_points = 0, dynamic_points = 0, masked_keypoints = 0, culled_points = 0;
  size_t frames_without_mask = 0, realtime_dropped = 0;
  Trajectory estimate;
  size_t processed = 0;
  size_t lost_count = 0;
  double ba_ms_before = 0.0;
  double last_inference_ms = -1.0;
  const auto start = std::chrono::steady_clock::now();
  // Deterministic runs load one frame ahead and announce it to the semantic thread, so the
  // network segments frame i+1 while frame i is tracked.
  std::optional<RgbdFrame> next;
  const auto load_frame = [&](size_t index) {
    RgbdFrame loaded = sequence.load(index);
    if (blackout && blackout->covers(index)) {
      loaded.bgr.setTo(cv::Scalar::all(0));
      if (!loaded.gray.empty()) loaded.gray.setTo(cv::Scalar::all(0));
      loaded.depth.setTo(cv::Scalar::all(0));
    }
    return loaded;
  };
  size_t relocalisations = 0;
  // Frames before the first map: a sequence that never starts (no depth readings) is told why,
  // after a second of video and again at the end, instead of ending with 0 poses.
  StartWatch start_watch(static_cast<size_t>(std::max(1.0, setup.config.camera.fps)));
  std::optional<size_t> first_pose_after_blackout;
  std::string first_method_after_blackout;
  for (size_t i = 0; i < frames; ++i) {
    if (interrupted()) break;
    if (dynamic.realtime) {
      // A live camera does not wait: skip to the newest frame whose time has come.
      const double elapsed =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const Timestamp t0 = sequence.timestamp(0);
      size_t newest = i;
      while (newest + 1 < frames && sequence.timestamp(newest + 1) - t0 <= elapsed) ++newest;
      realtime_dropped += newest - i;
      i = newest;
      const double wait = sequence.timestamp(i) - t0 - elapsed;
      if (wait > 0) std::this_thread::sleep_for(std::chrono::duration<double>(wait));
      next.reset();
    }
    const RgbdFrame frame = next ? std::move(*next) : load_frame(i);
    next.reset();
    if (!dynamic.realtime && i + 1 < frames) {
      next = load_frame(i + 1);
      if (i == 0) system.announce(frame);
      system.announce(*next);
    }
    if (frame.bgr.cols != camera.width || frame.bgr.rows != camera.height) {
      throw Error((sequence.directory() / sequence.files(i).rgb_file).string() + " is " +
                  std::to_string(frame.bgr.cols) + "x" + std::to_string(frame.bgr.rows) +
                  " but the config " + setup.config_file.string() + " says camera " +
                  std::to_string(camera.width) + "x" + std::to_string(camera.height));
    }
    const FrameReport report = system.process(frame);
    const TrackResult& result = report.tracking;
    spdlog::debug(
        "frame {} {:.6f}: {} ({}), {} of {} keypoints inliers{}; {} masked, {} tested, "
        "{} dynamic",
        i, frame.timestamp, to_string(result.state), to_string(result.method), result.num_inliers,
        result.num_keypoints, result.keyframe_inserted ? ", new keyframe" : "",
        report.dynamic.masked_keypoints, report.dynamic.tested_points,
        report.dynamic.dynamic_points);
    if (exporter && result.keyframe_inserted)
      exporter->remember_keyframe(system.map().max_keyframe_id(), frame.bgr, frame.depth,
                                  system.last_dynamic_mask());
    if (result.method == TrackingMethod::kRelocalisation) ++relocalisations;
    start_watch.update(result);
    if (blackout && i >= blackout->end() && !first_pose_after_blackout && result.T_world_camera) {
      first_pose_after_blackout = i;
      first_method_after_blackout = to_string(result.method);
    }
    if (result.T_world_camera) {
      trajectory.write(frame.timestamp, *result.T_world_camera);
      estimate.push_back({frame.timestamp, *result.T_world_camera});
    } else {
      ++lost_count;
      char line[96];
      std::snprintf(line, sizeof(line), "%zu %.6f %s\n", i, frame.timestamp,
                    to_string(result.state));
      lost << line << std::flush;
    }
    const MappingStats mapping = system.mapping_stats();
    const DynamicReport& dyn = report.dynamic;
    char row[384];
    std::snprintf(row, sizeof(row),
                  "%zu,%.6f,%s,%s,%d,%d,%d,%.3f,%.3f,%.3f,%zu,%.3f,%.3f,%.3f,%.3f,%d,%.3f,%d,%d,%d,"
                  "%d\n",
                  i, frame.timestamp, to_string(result.state), to_string(result.method),
                  result.num_keypoints, result.num_inliers, result.keyframe_inserted ? 1 : 0,
                  report.extraction_ms, report.tracking_ms,
                  mapping.local_ba_ms_total - ba_ms_before, mapping.queued_keyframes,
                  report.extraction_cpu_ms, report.tracking_cpu_ms, dyn.flow_ms,
                  dyn.semantic_wait_ms, dyn.mask_age_frames, dyn.geometry_ms, dyn.tested_points,
                  dyn.dynamic_points, dyn.masked_keypoints, dyn.culled_map_points);
    timing << row;
    if (mapping.local_ba_ms_total > ba_ms_before)
      local_mapping_ms.push_back(mapping.local_ba_ms_total - ba_ms_before);
    ba_ms_before = mapping.local_ba_ms_total;
    extraction_ms.push_back(report.extraction_ms);
    tracking_ms.push_back(report.tracking_ms);
    tracking_cpu_ms.push_back(report.tracking_cpu_ms);
    if (dynamic.mode != DynamicMode::off) flow_ms.push_back(dyn.flow_ms);
    if (uses_semantics(dynamic.mode)) {
      semantic_wait_ms.push_back(dyn.semantic_wait_ms);
      if (dyn.mask_age_frames < 0) {
        ++frames_without_mask;
      } else {
        mask_age_frames.push_back(dyn.mask_age_frames);
        mask_latency_ms.push_back(dyn.mask_latency_ms);
        // Count each mask's inference once (a mask may serve several frames in real time).
        if (dyn.semantic_inference_ms != last_inference_ms)
          semantic_ms.push_back(dyn.semantic_inference_ms);
        last_inference_ms = dyn.semantic_inference_ms;
      }
    }
    if (dyn.geometry_ran) {
      geometry_ms.push_back(dyn.geometry_ms);
      geometry_search_ms.push_back(dyn.geometry_search_ms);
    }
    tested_points += dyn.tested_points;
    dynamic_points += dyn.dynamic_points;
    masked_keypoints += dyn.masked_keypoints;
    culled_points += dyn.culled_map_points;
    ++processed;
    progress.update(processed, realtime_dropped);
  }
  progress.finish();
  system.shutdown();
  if (!flags.save_map.empty()) {
    const std::filesystem::path map_file = flags.save_map;
    const auto [saved_keyframes, saved_points] = system.save_map(map_file);
    std::cout << "map saved:    " << map_file.string() << " (" << saved_keyframes << " keyframes, "
              << saved_points << " map points, " << std::filesystem::file_size(map_file) / 1024
              << " KiB)\n";
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  write_tum_trajectory(out_dir / "keyframes.txt", system.keyframe_trajectory());
  const Trajectory refined = system.refined_trajectory();
  write_tum_trajectory(out_dir / "trajectory_refined.txt", refined);
  const MappingStats mapping = system.mapping_stats();
  if (exporter) write_map_exports(flags.export_map, flags.export_dense, *exporter, system.map());

  char line[512];
  std::snprintf(line, sizeof(line),
                "frames:       %zu processed, %zu tracked, %zu without pose (lost_frames.txt)\n"
                "speed:        %.1f fps overall (%.1f s)\n"
                "median ms:    extraction %.2f, tracking %.2f (tracking thread CPU %.2f)\n"
                "map:          %zu keyframes, %zu map points; mapping queue max %zu, local BA "
                "%.0f ms total\n",
                processed, processed - lost_count, lost_count,
                seconds > 0 ? processed / seconds : 0.0, seconds, median(extraction_ms),
                median(tracking_ms), median(tracking_cpu_ms), mapping.keyframes_in_map,
                mapping.map_points, mapping.max_queued_keyframes, mapping.local_ba_ms_total);
  std::cout << line;
  std::snprintf(line, sizeof(line),
                "mapping:      %zu keyframes processed, %zu culled; points: %zu triangulated, "
                "%zu fused, %zu culled, %zu BA outlier observations removed\n",
                mapping.processed_keyframes, mapping.keyframes_culled, mapping.points_triangulated,
                mapping.points_fused, mapping.points_culled, mapping.ba_outliers_removed);
  std::cout << line;
  if (system_options.place.loop_closing) print_loop_stats(mapping);
  std::cout << "output:       " << (out_dir / "trajectory.txt").string() << " ("
            << trajectory.count()
            << " poses), trajectory_refined.txt, keyframes.txt, lost_frames.txt, timing.csv\n";
  std::optional<AteResult> ate_tracked;
  std::optional<AteResult> ate_refined;
  if (sequence.ground_truth() && estimate.size() >= 3) {
    const std::tuple<const char*, const Trajectory*, std::optional<AteResult>*> evaluated[] = {
        {"trajectory.txt        ", &estimate, &ate_tracked},
        {"trajectory_refined.txt", &refined, &ate_refined}};
    for (const auto& [name, poses, slot] : evaluated) {
      try {
        const AteResult ate = compute_ate(*sequence.ground_truth(), *poses);
        std::snprintf(line, sizeof(line),
                      "ATE %s (SE(3) aligned, %zu poses): RMSE %.4f m, mean %.4f m, median "
                      "%.4f m, max %.4f m\n",
                      name, ate.error.count, ate.error.rmse, ate.error.mean, ate.error.median,
                      ate.error.max);
        std::cout << line;
        *slot = ate;
      } catch (const Error& e) {
        std::cout << "ATE " << name << ": not computed: " << e.what() << "\n";
      }
    }
  }

  // Blackout: how soon a pose came back, and how good the poses after the return are (errors
  // of the whole run's alignment, restricted to frames from the return on).
  std::optional<ErrorStats> after_return;
  nlohmann::ordered_json blackout_json;  // a stats.json member, null without --blackout
  if (blackout) {
    std::snprintf(line, sizeof(line), "blackout:     frames %zu-%zu black, %zu relocalisations; ",
                  blackout->first, blackout->end() - 1, relocalisations);
    std::cout << line;
    if (first_pose_after_blackout) {
      std::snprintf(line, sizeof(line), "first pose after the return at frame %zu (+%zu) by %s\n",
                    *first_pose_after_blackout, *first_pose_after_blackout - blackout->end(),
                    first_method_after_blackout.c_str());
      std::cout << line;
    } else {
      std::cout << "no pose after the return\n";
    }
    if (ate_tracked && blackout->end() < frames) {
      const Timestamp returned = sequence.timestamp(blackout->end());
      std::vector<double> errors;
      for (const AtePair& pair : ate_tracked->pairs) {
        if (pair.est_timestamp >= returned) errors.push_back(pair.error);
      }
      if (!errors.empty()) {
        after_return = compute_error_stats(errors);
        std::snprintf(line, sizeof(line),
                      "              after the return: %zu poses, error RMSE %.4f m, max %.4f m\n",
                      after_return->count, after_return->rmse, after_return->max);
        std::cout << line;
      }
    }
    blackout_json = {
        {"first", blackout->first},
        {"count", blackout->count},
        {"frames_to_first_pose",
         first_pose_after_blackout ? static_cast<long>(*first_pose_after_blackout - blackout->end())
                                   : -1L},
        {"after_return_rmse_m", after_return ? after_return->rmse : -1.0},
        {"after_return_max_m", after_return ? after_return->max : -1.0}};
  }

  // Per-module timing and the dynamic-feature totals, printed and written to stats.json.
  const TimingSummary t_extraction = summarize(extraction_ms);
  const TimingSummary t_semantic = summarize(semantic_ms);
  const TimingSummary t_semantic_wait = summarize(semantic_wait_ms);
  const TimingSummary t_geometry = summarize(geometry_ms);
  const TimingSummary t_search = summarize(geometry_search_ms);
  const TimingSummary t_flow = summarize(flow_ms);
  const TimingSummary t_tracking = summarize(tracking_ms);
  const TimingSummary t_mapping = summarize(local_mapping_ms);
  const TimingSummary mask_age = summarize(mask_age_frames);
  const TimingSummary mask_latency = summarize(mask_latency_ms);
  std::snprintf(line, sizeof(line),
                "timing ms:    median/mean/p95  extraction %.1f/%.1f/%.1f  semantic inference "
                "%.1f/%.1f/%.1f (waited %.1f/%.1f/%.1f)\n"
                "              geometry %.1f/%.1f/%.1f (search %.1f)  flow+H %.1f  tracking "
                "%.1f/%.1f/%.1f  local BA %.1f/%.1f/%.1f\n",
                t_extraction.median, t_extraction.mean, t_extraction.p95, t_semantic.median,
                t_semantic.mean, t_semantic.p95, t_semantic_wait.median, t_semantic_wait.mean,
                t_semantic_wait.p95, t_geometry.median, t_geometry.mean, t_geometry.p95,
                t_search.median, t_flow.median, t_tracking.median, t_tracking.mean, t_tracking.p95,
                t_mapping.median, t_mapping.mean, t_mapping.p95);
  std::cout << line;
  std::snprintf(line, sizeof(line),
                "dynamic:      mode %s; %zu keypoints tested, %zu flagged by geometry, %zu "
                "dropped before tracking, %zu map points culled; mask age median %.0f frames "
                "(%.0f ms), %zu frames without mask, %zu frames dropped by the real-time feed\n",
                to_string(dynamic.mode), tested_points, dynamic_points, masked_keypoints,
                culled_points, mask_age.median, mask_latency.median, frames_without_mask,
                realtime_dropped);
  std::cout << line;

  {
    const double fps = seconds > 0 ? static_cast<double>(processed) / seconds : 0.0;
    nlohmann::ordered_json stats = {{"sequence", sequence.directory().string()},
                                    {"mode", to_string(dynamic.mode)},
                                    {"realtime", dynamic.realtime},
                                    {"interrupted", interrupted()},
                                    {"frames", processed},
                                    {"lost_frames", lost_count},
                                    {"relocalisations", relocalisations}};
    if (!blackout_json.is_null()) stats["blackout"] = blackout_json;
    stats["realtime_dropped_frames"] = realtime_dropped;
    stats["seconds"] = seconds;
    stats["fps"] = fps;
    stats["timing_ms"] = {
        {"extraction", to_json(t_extraction)},       {"semantic", to_json(t_semantic)},
        {"semantic_wait", to_json(t_semantic_wait)}, {"geometry", to_json(t_geometry)},
        {"geometry_search", to_json(t_search)},      {"flow_homography", to_json(t_flow)},
        {"tracking", to_json(t_tracking)},           {"local_mapping", to_json(t_mapping)}};
    stats["dynamic"] = {{"tested_points", tested_points},
                        {"dynamic_points", dynamic_points},
                        {"masked_keypoints", masked_keypoints},
                        {"culled_map_points", culled_points},
                        {"frames_without_mask", frames_without_mask}};
    stats["mask_latency"] = {{"frames", to_json(mask_age)}, {"ms", to_json(mask_latency)}};
    stats["map"] = {{"keyframes", mapping.keyframes_in_map}, {"map_points", mapping.map_points}};
    stats["loops"] = {{"enabled", system_options.place.loop_closing},
                      {"closed", mapping.loops_closed},
                      {"global_ba_applied", mapping.global_ba_applied}};
    const std::pair<const char*, const std::optional<AteResult>*> ates[] = {
        {"ate", &ate_tracked}, {"ate_refined", &ate_refined}};
    for (const auto& [key, ate] : ates) {
      if (!*ate) continue;
      stats[key] = {{"rmse", (*ate)->error.rmse},
                    {"mean", (*ate)->error.mean},
                    {"median", (*ate)->error.median},
                    {"max", (*ate)->error.max},
                    {"poses", (*ate)->error.count}};
    }
    std::ofstream json = open_output(out_dir / "stats.json");
    // Paths are not always UTF-8 (a Latin-1 folder name); replace invalid bytes instead of
    // throwing, so the summary is always written.
    json << stats.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
  }
  std::cout << "stats:        " << (out_dir / "stats.json").string() << "\n";
  if (interrupted()) {
    std::cout << "interrupted after " << processed << " of " << frames
              << " frames; trajectory.txt holds every pose computed so far\n";
    return kInterruptedExit;
  }
  if (start_watch.never_started()) {  // no frame got a pose, so the trajectory is empty
    spdlog::error("{}", start_watch.reason());
    return kNeverStartedExit;
  }
  return 0;
}

Command add_run_command(CLI::App& root) {
  CLI::App* app = root.add_subcommand(
      "run",
      "run SLAM on an RGB-D sequence and write the trajectory.\n"
      "Reads a sequence in TUM layout (rgb.txt, depth.txt or associations.txt, optional "
      "groundtruth.txt)\nand writes OUT/trajectory.txt (every tracked frame), "
      "OUT/trajectory_refined.txt, OUT/lost_frames.txt,\nOUT/keyframes.txt, OUT/timing.csv and "
      "OUT/stats.json. With ground truth, prints ATE.");
  auto flags = std::make_shared<RunFlags>();
  app->add_option("--sequence", flags->sequence, "sequence folder")->required();
  app->add_option("--config", flags->config,
                  "camera/system config YAML (default: SEQUENCE/config.yaml when it exists, "
                  "else required; presets in config/)");
  app->add_option("--out", flags->out, "output folder")->capture_default_str();
  app->add_option("--max-frames", flags->max_frames, "process at most this many frames (0 = all)")
      ->check(in_range(size_t{0}, size_t{1000000000}))
      ->capture_default_str();
  app->add_flag("--no-local-mapping", flags->no_local_mapping,
                "track only: keyframes enter the map but are never refined (debugging)");
  app->add_option("--dynamic", flags->dynamic,
                  "dynamic-scene mode: off | semantic | geometry | full | exhaustive | auto "
                  "(auto = full when the segmentation model loads, else geometry)")
      ->check(CLI::IsMember({"off", "semantic", "geometry", "full", "exhaustive", "auto"}))
      ->capture_default_str();
  app->add_option("--model", flags->model,
                  "segmentation metadata YAML (default: the shipped models/pspnet/pspnet.yaml)");
  app->add_flag("--realtime", flags->realtime,
                "feed frames at the sequence's rate (late frames are dropped) and never wait for "
                "segmentation or local mapping: use the newest mask, warped into the frame "
                "(default: deterministic, each frame waits for its mask and for local mapping "
                "to finish the previous keyframe)");
  app->add_option("--mask-margin", flags->mask_margin,
                  "dilation of the semantic dynamic mask (pixels)")
      ->check(in_range(0, 100))
      ->capture_default_str();
  app->add_option("--keyframe-ratio", flags->keyframe_ratio,
                  "a frame becomes a keyframe when it tracks fewer than this share of its "
                  "reference keyframe's points (ORB-SLAM2: 0.75; higher = denser keyframes)")
      ->check(in_range(0.01, 1.0))
      ->capture_default_str();
  app->add_option("--vocabulary", flags->vocabulary,
                  "ORB bag-of-words vocabulary for relocalisation and loop closing (default: the "
                  "shipped models/vocabulary/orb_k10_l5.pspvoc)");
  app->add_flag("--no-relocalization", flags->no_relocalization,
                "do not relocalise when tracking is lost (and do not load the vocabulary)");
  app->add_option("--loop-closing", flags->loop_closing,
                  "loop closing thread (detection, essential-graph correction, global BA); auto = "
                  "on when the vocabulary file exists")
      ->check(CLI::IsMember({"on", "off", "auto"}))
      ->capture_default_str();
  app->add_option("--save-map", flags->save_map,
                  "write the final map to this file (binary, see docs/place_recognition.md)");
  CLI::Option* load_map =
      app->add_option("--load-map", flags->load_map,
                      "start from this saved map: the first frame is relocalised in it")
          ->check(CLI::ExistingFile);
  app->add_flag("--localization", flags->localization,
                "localisation only (needs --load-map): track in the map, never add to it")
      ->needs(load_map);
  app->add_option("--blackout", flags->blackout,
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
  app->add_option("--cull-hits", flags->cull_hits,
                  "erase a map point after it lay on dynamic pixels in this many frames")
      ->check(in_range(1, 1000))
      ->capture_default_str();
  app->add_option("--export-map", flags->export_map,
                  "write the final static map points as a PLY point cloud (dynamic points never "
                  "enter the map or are culled from it)");
  app->add_option("--export-dense", flags->export_dense,
                  "also write a dense PLY cloud back-projected from the keyframes' depth at their "
                  "final poses, dynamic pixels left out (1 cm voxels, every 4th pixel)");
  return {app, [flags](const GlobalOptions& global) { return run_slam(*flags, global); }};
}

}  // namespace pspslam::cli
