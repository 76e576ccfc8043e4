#include "pspslam/session/sequence_runner.h"

#include <spdlog/spdlog.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

#include "pspslam/core/error.h"
#include "pspslam/core/interrupt.h"
#include "pspslam/core/progress.h"
#include "pspslam/core/thread_cpu_time.h"
#include "pspslam/io/input_frame.h"
#include "pspslam/io/point_cloud_ply.h"
#include "pspslam/io/sequence_source.h"
#include "pspslam/map/map.h"
#include "pspslam/semantic/segmenter.h"
#include "pspslam/semantic/segmenter_metadata.h"
#include "pspslam/session/run_report.h"
#include "pspslam/session/start_watch.h"

namespace pspslam {
namespace {

// --export-map / --export-dense, after shutdown (local mapping has refined the poses).
void write_map_exports(const RunOutputs& outputs, const MapExporter& exporter, const Map& map,
                       std::ostream& out) {
  const std::vector<std::string> comment = {"pspslam static map, world frame (metres)"};
  if (!outputs.export_map.empty()) {
    const std::vector<ColoredPoint> cloud = exporter.map_points(map);
    write_point_cloud_ply(outputs.export_map, cloud, comment);
    out << "map export:   " << outputs.export_map.string() << " (" << cloud.size() << " points)\n";
  }
  if (!outputs.export_dense.empty()) {
    const std::vector<ColoredPoint> cloud = exporter.dense_cloud(map, DenseCloudOptions{});
    write_point_cloud_ply(outputs.export_dense, cloud, comment);
    out << "map export:   " << outputs.export_dense.string() << " (" << cloud.size()
        << " points, from " << exporter.remembered_keyframes() << " keyframe images)\n";
  }
}

void log_frame(const InputFrame& frame, const FrameReport& report) {
  const TrackResult& result = report.tracking;
  spdlog::debug(
      "frame {} {:.6f}: {} ({}), {} of {} keypoints inliers{}; {} masked, {} tested, "
      "{} dynamic{}",
      frame.index, frame.timestamp, to_string(result.state), to_string(result.method),
      result.num_inliers, result.num_keypoints, result.keyframe_inserted ? ", new keyframe" : "",
      report.dynamic.masked_keypoints, report.dynamic.tested_points, report.dynamic.dynamic_points,
      result.initialization_matches > 0
          ? fmt::format("; two-view: {} matches, {}", result.initialization_matches,
                        to_string(result.initialization_model))
          : std::string());
}

}  // namespace

SequenceRunner::SequenceRunner(RunOptions options, std::ostream& out)
    : SequenceRunner(open_run_input(options), options, out) {}

SequenceRunner::SequenceRunner(RunInput input, RunOptions options, std::ostream& out)
    : options_(std::move(options)),
      out_(out),
      input_(std::move(input)),
      limits_(apply_sensor_limits(input_.config.camera.type, options_.system)),
      frames_(input_.source->frame_count().value_or(options_.max_frames)),
      log_(options_.outputs.folder),
      images_(options_.outputs.masks, options_.outputs.overlays),
      statistics_(options_.system.dynamic.mode, options_.blackout,
                  options_.system.dynamic.stale_mask_frames) {
  const SystemOptions& system = options_.system;
  const DynamicOptions& dynamic = system.dynamic;
  if (options_.max_frames > 0 && (frames_ == 0 || frames_ > options_.max_frames))
    frames_ = options_.max_frames;
  out_ << input_.source->describe();
  out_ << "dynamic:      " << to_string(dynamic.mode)
       << (!uses_semantics(dynamic.mode) ? ""
           : dynamic.semantic_masks.empty()
               ? " (model " + dynamic.model.string() + ")"
               : " (semantic masks from " + dynamic.semantic_masks.string() + ")")
       << (dynamic.realtime ? ", real-time feed" : ", deterministic (waits for each mask)")
       << (limits_.dynamic_note.empty() ? "" : "; " + limits_.dynamic_note) << "\n";
  if (!system.map_file.empty()) {
    out_ << "map:          " << system.map_file.string()
         << (system.localization_only ? " (localisation only)" : " (extended)") << "\n";
  }
  out_ << "loop closing: " << (system.place.loop_closing ? "on" : "off") << "\n";
  // Keypoint fates cost a second extraction per frame: only for the overlays.
  if (images_.writes_overlays()) {
    options_.system.record_keypoint_fates = true;
    if (uses_semantics(dynamic.mode)) {
      const SegmenterMetadata model = load_segmenter_metadata(dynamic.model);
      const std::vector<std::string>& names = dynamic.semantic.dynamic_classes.empty()
                                                  ? model.dynamic_classes
                                                  : dynamic.semantic.dynamic_classes;
      images_.set_classes({model.classes, class_ids(model.classes, names, model.file.string())});
    }
  }
  // The config as the run uses it (a --sensor override applied; the original's comments are not
  // kept): `pspslam run --config OUT/run_config.yaml` repeats the run.
  save_config(options_.outputs.folder / "run_config.yaml", input_.config);
  // The semantic thread's frame budget in live runs is the camera's frame period.
  if (input_.config.camera.fps > 0.0)
    options_.system.dynamic.frame_period_ms = 1000.0 / input_.config.camera.fps;
  system_ = std::make_unique<System>(input_.config, options_.system);
  if (system_->tracks_people()) people_log_.emplace(options_.outputs.folder);
  if (!options_.outputs.export_map.empty() || !options_.outputs.export_dense.empty())
    exporter_.emplace(input_.config.camera.pinhole);
  if (options_.occupancy.enabled)
    occupancy_ = std::make_unique<OccupancyRun>(input_.config.camera.pinhole, options_.occupancy);
}

SequenceRunner::~SequenceRunner() = default;

std::optional<InputFrame> SequenceRunner::next_frame() {
  if (frames_ > 0 && delivered_ >= frames_) return std::nullopt;
  std::optional<InputFrame> loaded = input_.source->next();
  if (!loaded) return std::nullopt;
  ++delivered_;
  const size_t before = statistics_.realtime_dropped();
  statistics_.add_dropped(input_.source->stats().dropped - before);
  if (options_.blackout && options_.blackout->covers(loaded->index)) {
    loaded->bgr.setTo(cv::Scalar::all(0));
    if (!loaded->gray.empty()) loaded->gray.setTo(cv::Scalar::all(0));
    loaded->depth.setTo(cv::Scalar::all(0));
    if (!loaded->right.empty()) loaded->right.setTo(cv::Scalar::all(0));
  }
  if (options_.blackout && !blackout_return_ && loaded->index >= options_.blackout->end())
    blackout_return_ = loaded->timestamp;
  return loaded;
}

void SequenceRunner::check_frame_size(const InputFrame& frame) const {
  const PinholeCamera& camera = input_.config.camera.pinhole;
  if (frame.bgr.cols != camera.width || frame.bgr.rows != camera.height) {
    throw Error((std::filesystem::path(input_.source->name()) / frame.name).string() + " is " +
                std::to_string(frame.bgr.cols) + "x" + std::to_string(frame.bgr.rows) +
                " but the config " + input_.config_file.string() + " says camera " +
                std::to_string(camera.width) + "x" + std::to_string(camera.height));
  }
}

RunOutcome SequenceRunner::run() {
  InterruptGuard interrupt_guard;
  // A live stream of unknown length has no bar to fill.
  ProgressBar progress("slam", frames_, std::cerr, options_.progress && frames_ > 0,
                       options_.system.dynamic.realtime);
  const auto start = std::chrono::steady_clock::now();
  // Frames before the first map: a sequence that never starts (no depth readings) is told why,
  // after a second of video and again at the end, instead of ending with 0 poses.
  StartWatch start_watch(static_cast<size_t>(std::max(1.0, input_.config.camera.fps)));
  feed_frames(progress, start_watch);
  if (observer_) observer_->run_ended();
  progress.finish();
  system_->shutdown();
  save_map();
  finish(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  return outcome(start_watch);
}

void SequenceRunner::feed_frames(ProgressBar& progress, StartWatch& start_watch) {
  const bool realtime = options_.system.dynamic.realtime;
  MappingStats mapping_before;
  // Deterministic runs load one frame ahead and announce it to the semantic thread, so the
  // network segments frame i+1 while frame i is tracked.
  std::optional<InputFrame> next;
  for (bool first = true; !interrupted(); first = false) {
    std::optional<InputFrame> current = next ? std::move(next) : next_frame();
    next.reset();
    if (!current) break;
    const InputFrame& frame = *current;
    if (!realtime) {
      next = next_frame();
      if (first) system_->announce(frame);
      if (next) system_->announce(*next);
    }
    check_frame_size(frame);
    const double observer_cpu = ask_observer_detail();
    const FrameReport report = system_->process(frame);
    const MappingStats mapping = record_frame(frame, report, start_watch, mapping_before);
    progress.update(statistics_.processed(), statistics_.realtime_dropped());
    if (observer_) {
      const double cpu_before = thread_cpu_ms();
      observer_->frame_done({frame, report, *system_, statistics_, mapping, estimate_, frames_,
                             &input_.config.camera.pinhole, occupancy_.get()});
      statistics_.observer_cpu_ms.push_back(observer_cpu + thread_cpu_ms() - cpu_before);
    }
  }
}

double SequenceRunner::ask_observer_detail() {
  if (!observer_) return 0.0;
  const double cpu_before = thread_cpu_ms();
  const RunObserver::Detail detail = observer_->wants_detail();
  const double observer_cpu = thread_cpu_ms() - cpu_before;
  const bool overlays = images_.writes_overlays();
  system_->set_record_keypoint_fates(overlays || detail.fates, overlays || detail.masked_keypoints);
  return observer_cpu;
}

MappingStats SequenceRunner::record_frame(const InputFrame& frame, const FrameReport& report,
                                          StartWatch& start_watch, MappingStats& mapping_before) {
  std::optional<double> arrival_to_pose_ms;
  if (frame.arrival) {
    arrival_to_pose_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - *frame.arrival)
            .count();
    statistics_.arrival_to_pose_ms.push_back(*arrival_to_pose_ms);
  }
  const TrackResult& result = report.tracking;
  log_frame(frame, report);
  write_images(frame, report);
  if (exporter_ && result.keyframe_inserted)
    exporter_->remember_keyframe(system_->map().max_keyframe_id(), frame.bgr, frame.depth,
                                 system_->last_dynamic_mask());
  if (occupancy_ && result.keyframe_inserted)
    occupancy_->add_keyframe(system_->map().keyframe(system_->map().max_keyframe_id()), frame.depth,
                             system_->last_dynamic_mask());
  if (start_watch.update(result)) spdlog::warn("{}", start_watch.reason());
  // The frame that started a monocular map also placed frames before it (oldest first).
  estimate_.insert(estimate_.end(), result.earlier_frames.begin(), result.earlier_frames.end());
  log_.write_earlier(result.earlier_frames);
  if (result.T_world_camera) estimate_.push_back({frame.timestamp, *result.T_world_camera});
  const MappingStats mapping = system_->mapping_stats();
  const LocalBaTime local_ba{mapping.local_ba_ms_total - mapping_before.local_ba_ms_total,
                             mapping.local_ba_cpu_ms_total - mapping_before.local_ba_cpu_ms_total};
  log_.write(frame.index, frame.timestamp, report, local_ba.wall_ms, mapping, arrival_to_pose_ms);
  if (people_log_) people_log_->write(frame.index, frame.timestamp, report.people);
  if (result.restart_due) {
    // The new map has its own world frame and scale: the old poses would corrupt the file.
    log_.forget_poses();
    estimate_.clear();
    if (people_log_) people_log_->forget_rows();
  }
  statistics_.add_frame(frame.index, report, local_ba);
  mapping_before = mapping;
  return mapping;
}

void SequenceRunner::save_map() {
  if (options_.outputs.save_map.empty()) return;
  const std::filesystem::path& map_file = options_.outputs.save_map;
  const auto [saved_keyframes, saved_points] = system_->save_map(map_file);
  out_ << "map saved:    " << map_file.string() << " (" << saved_keyframes << " keyframes, "
       << saved_points << " map points, " << std::filesystem::file_size(map_file) / 1024
       << " KiB)\n";
}

RunOutcome SequenceRunner::outcome(const StartWatch& start_watch) {
  if (interrupted()) {
    out_ << "interrupted after " << statistics_.processed()
         << (frames_ > 0 ? " of " + std::to_string(frames_) : std::string())
         << " frames; trajectory.txt holds every pose computed so far\n";
    return RunOutcome::interrupted;
  }
  const FrameSourceStats source = input_.source->stats();
  if (source.disconnected) {
    spdlog::error("{} after {} frames; the outputs hold every pose computed so far",
                  source.end_reason, statistics_.processed());
    return RunOutcome::disconnected;
  }
  if (start_watch.never_started()) {  // no frame got a pose, so the trajectory is empty
    spdlog::error("{}", start_watch.reason());
    return RunOutcome::never_started;
  }
  return RunOutcome::completed;
}

void SequenceRunner::write_images(const InputFrame& frame, const FrameReport& report) {
  if (!images_.writes_masks() && !images_.writes_overlays()) return;
  const std::filesystem::path rgb_file = frame.name;
  if (images_.writes_masks())
    images_.write_mask(rgb_file, system_->last_dynamic_mask(), frame.bgr.size());
  if (images_.writes_overlays())
    images_.write_overlay(rgb_file, frame.bgr, system_->last_semantic_labels(), report.keypoints);
}

void SequenceRunner::finish(double seconds) {
  const std::filesystem::path& out_dir = options_.outputs.folder;
  // The main map of the atlas (most poses) gives the run's files; maps that never merged with it
  // get their own, since their world frames differ.
  const std::vector<MapTrajectory> final_maps =
      split_by_map(system_->refined_trajectory(), system_->refined_map_ids());
  const Trajectory& refined = final_maps.front().poses;
  write_tum_trajectory(out_dir / "keyframes.txt",
                       system_->keyframe_trajectory(final_maps.front().map_id));
  write_tum_trajectory(out_dir / "trajectory_refined.txt", refined);
  for (size_t m = 1; m < final_maps.size(); ++m) {
    const std::uint32_t id = final_maps[m].map_id;
    write_tum_trajectory(other_map_file(out_dir, "trajectory_refined", id), final_maps[m].poses);
    write_tum_trajectory(other_map_file(out_dir, "keyframes", id),
                         system_->keyframe_trajectory(id));
  }
  if (options_.outputs.kitti_trajectory) {
    write_kitti_trajectory(out_dir / "trajectory_kitti.txt", estimate_);
    write_kitti_trajectory(out_dir / "trajectory_refined_kitti.txt", refined);
  }
  const MappingStats mapping = system_->mapping_stats();
  if (exporter_) write_map_exports(options_.outputs, *exporter_, system_->map(), out_);
  if (occupancy_) occupancy_->finish(system_->keyframe_trajectory(final_maps.front().map_id), out_);
  const AtlasSummary atlas{.new_map_after_seconds = options_.system.tracker.new_map_after_seconds,
                           .maps = statistics_.frames_per_map(),
                           .merges = mapping.map_merges,
                           .maps_at_end = mapping.maps,
                           .final_maps = final_maps};
  const nlohmann::ordered_json people =
      people_log_
          ? people_log_->summary(options_.sequence, input_.source->ground_truth(), estimate_)
          : nlohmann::ordered_json();
  write_run_report({.options = options_,
                    .statistics = statistics_,
                    .mapping = mapping,
                    .source = *input_.source,
                    .estimate = estimate_,
                    .refined = refined,
                    .atlas = atlas,
                    .frames = frames_,
                    .blackout_return = blackout_return_,
                    .seconds = seconds,
                    .interrupted = interrupted(),
                    .sensor = input_.config.camera.type,
                    .config_file = input_.config_file,
                    .requested_mode = limits_.requested_mode,
                    .dynamic_note = limits_.dynamic_note,
                    .occupancy = occupancy_ ? &occupancy_->json() : nullptr,
                    .people = people_log_ ? &people : nullptr},
                   out_);
}

}  // namespace pspslam
