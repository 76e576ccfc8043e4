#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <ostream>

#include "pspslam/core/types.h"
#include "pspslam/io/sequence_setup.h"
#include "pspslam/session/frame_images.h"
#include "pspslam/session/frame_log.h"
#include "pspslam/session/run_options.h"
#include "pspslam/session/run_statistics.h"
#include "pspslam/system/map_export.h"
#include "pspslam/system/system.h"

namespace pspslam {

struct RgbdFrame;

// Runs the System over a recorded sequence and writes the run's files (`pspslam run`): the
// per-frame log (frame_log.h) while it goes, then keyframes.txt, trajectory_refined.txt, the map
// files asked for and the report (run_report.h). Frames are fed as a deterministic run wants
// them (one ahead, announced to the semantic thread) or, with options.system.dynamic.realtime,
// at the sequence's rate, dropping the frames whose time has passed.
class SequenceRunner {
 public:
  // Opens the sequence and its config, creates the per-frame files and the System; prints the
  // setup to `out`. Call prepare_run_outputs() first. Throws pspslam::Error.
  SequenceRunner(RunOptions options, std::ostream& out);
  ~SequenceRunner();
  SequenceRunner(const SequenceRunner&) = delete;
  SequenceRunner& operator=(const SequenceRunner&) = delete;

  // Processes the frames (until the end, max_frames or an interrupt), shuts the system down and
  // writes the final outputs and the report. Call once.
  RunOutcome run();

 private:
  RgbdFrame load_frame(size_t index) const;
  void check_frame_size(size_t index, const RgbdFrame& frame) const;
  void write_images(size_t index, const RgbdFrame& frame, const FrameReport& report);
  void finish(double seconds);

  RunOptions options_;
  std::ostream& out_;
  SequenceSetup setup_;
  size_t frames_ = 0;  // frames to process
  FrameLog log_;
  FrameImageWriter images_;  // --save-masks / --save-overlays
  std::unique_ptr<System> system_;
  std::optional<MapExporter> exporter_;  // with --export-map / --export-dense
  RunStatistics statistics_;
  Trajectory estimate_;
};

}  // namespace pspslam
