#pragma once

#include <cstddef>
#include <filesystem>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <ostream>

#include "pspslam/core/types.h"
#include "pspslam/io/frame_source.h"
#include "pspslam/session/atlas_report.h"
#include "pspslam/session/run_options.h"
#include "pspslam/session/run_statistics.h"
#include "pspslam/system/system.h"

namespace pspslam {

// What the end of a run knows.
struct RunReportInput {
  const RunOptions& options;
  const RunStatistics& statistics;
  const MappingStats& mapping;
  const FrameSource& source;   // ground truth, name and how the input ended
  const Trajectory& estimate;  // the poses of trajectory.txt
  const Trajectory& refined;   // trajectory_refined.txt (the main map of the atlas)
  const AtlasSummary& atlas;
  size_t frames = 0;  // frames the run was to process (0: until the input ended)
  // Timestamp of the first frame after a --blackout, when the run got there.
  std::optional<Timestamp> blackout_return;
  double seconds = 0.0;
  bool interrupted = false;
  SensorType sensor = SensorType::rgbd;
  std::filesystem::path config_file;  // the config the run read (stats.json "config")
  // What the sensor could not run (system/frame_builder.h apply_sensor_limits): the mode asked
  // for, and the note of the summary.
  DynamicMode requested_mode = DynamicMode::off;
  std::string dynamic_note;
  const nlohmann::ordered_json* occupancy = nullptr;  // stats.json "occupancy"; null: none
  // stats.json "people" (session/people_log.h); null: the run tracked no people.
  const nlohmann::ordered_json* people = nullptr;
};

// The run's summary: printed to `out` (frames, speed, map, loops, ATE against the sequence's
// ground truth, blackout recovery, per-module timing, dynamic-feature totals) and written to
// OUT/stats.json, also for an interrupted run.
void write_run_report(const RunReportInput& input, std::ostream& out);

}  // namespace pspslam
