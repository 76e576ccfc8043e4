#pragma once

#include <cstddef>
#include <filesystem>
#include <memory>
#include <optional>
#include <ostream>

#include "pspslam/config/config.h"
#include "pspslam/core/types.h"
#include "pspslam/io/frame_source.h"
#include "pspslam/session/frame_images.h"
#include "pspslam/session/frame_log.h"
#include "pspslam/session/people_log.h"
#include "pspslam/session/run_input.h"
#include "pspslam/session/run_observer.h"
#include "pspslam/session/run_options.h"
#include "pspslam/session/run_statistics.h"
#include "pspslam/system/frame_builder.h"
#include "pspslam/system/map_export.h"
#include "pspslam/system/system.h"

namespace pspslam {

struct InputFrame;
class ProgressBar;
class StartWatch;

// Runs the System over a stream of frames and writes the run's files (`pspslam run`): the
// per-frame log (frame_log.h) while it goes, then keyframes.txt, trajectory_refined.txt, the map
// files asked for and the report (run_report.h). Frames are fed as a deterministic run wants
// them (one ahead, announced to the semantic thread) or, with options.system.dynamic.realtime,
// as the source delivers them (a paced sequence or a camera drops the frames it cannot hand over
// in time). Where the frames come from is the FrameSource's business.
class SequenceRunner {
 public:
  // Opens the input options names (open_run_input) and runs over it.
  SequenceRunner(RunOptions options, std::ostream& out);
  // Creates the per-frame files and the System for `input`; prints the setup to `out`. Call
  // prepare_run_outputs() first. Throws pspslam::Error.
  SequenceRunner(RunInput input, RunOptions options, std::ostream& out);
  ~SequenceRunner();
  SequenceRunner(const SequenceRunner&) = delete;
  SequenceRunner& operator=(const SequenceRunner&) = delete;

  // Shows every frame to `observer` (the live viewer; not owned, must outlive run()); null: none.
  void watch(RunObserver* observer) { observer_ = observer; }

  // Processes the frames (until the end, max_frames or an interrupt), shuts the system down and
  // writes the final outputs and the report. Call once.
  RunOutcome run();

 private:
  // The frame loop: every frame processed, logged and shown to the observer.
  void feed_frames(ProgressBar& progress, StartWatch& start_watch);
  std::optional<InputFrame> next_frame();
  void check_frame_size(const InputFrame& frame) const;
  // Asks the observer what it shows of the next frame; returns the CPU milliseconds that took.
  double ask_observer_detail();
  // The frame's pose, log line, images and statistics; returns the mapping totals after it.
  MappingStats record_frame(const InputFrame& frame, const FrameReport& report,
                            StartWatch& start_watch, MappingStats& mapping_before);
  void save_map();  // --save-map
  RunOutcome outcome(const StartWatch& start_watch);
  void write_images(const InputFrame& frame, const FrameReport& report);
  void finish(double seconds);

  RunOptions options_;
  std::ostream& out_;
  RunInput input_;
  // What the sensor cannot run, taken out of options_.system before anything else reads it.
  SensorLimits limits_;
  size_t frames_ = 0;     // frames to process; 0 = until the source ends
  size_t delivered_ = 0;  // frames taken from the source
  std::optional<Timestamp> blackout_return_;
  FrameLog log_;
  std::optional<PeopleLog> people_log_;  // runs that track people (System::tracks_people)
  FrameImageWriter images_;              // --save-masks / --save-overlays
  std::unique_ptr<System> system_;
  std::optional<MapExporter> exporter_;      // with --export-map / --export-dense
  std::unique_ptr<OccupancyRun> occupancy_;  // with --occupancy
  RunStatistics statistics_;
  Trajectory estimate_;
  RunObserver* observer_ = nullptr;
};

}  // namespace pspslam
