#pragma once

#include <cstddef>
#include <optional>
#include <string>

#include "pspslam/core/types.h"
#include "pspslam/io/input_frame.h"

namespace pspslam {

// How a stream of frames ended, for the run's report.
struct FrameSourceStats {
  // Frames the source discarded because the caller was busy: a real-time feed of a recorded
  // sequence skips frames whose time has passed, a live camera keeps only the newest frames.
  size_t dropped = 0;
  // The stream stopped before its normal end (a camera unplugged or silent); `end_reason` says
  // what happened. A recorded sequence never disconnects.
  bool disconnected = false;
  std::string end_reason;
};

// Where the frames of a run come from: a recorded sequence (SequenceSource) or a live camera
// (capture/). The frame loop (session/SequenceRunner) sees only this interface.
class FrameSource {
 public:
  virtual ~FrameSource() = default;

  // The next frame (InputFrame::index counts delivered frames from 0), or nullopt at the end of
  // the stream. A live source blocks until its device delivers. Errors throw pspslam::Error.
  virtual std::optional<InputFrame> next() = 0;

  // How many frames the stream holds when that is known in advance (a recorded sequence).
  virtual std::optional<size_t> frame_count() const { return std::nullopt; }

  // What the run reads, for stats.json and messages: a folder path or "freenect:0".
  virtual std::string name() const = 0;

  // Multi-line description for the start of a run (frames, time span, device, ...).
  virtual std::string describe() const = 0;

  // The ground-truth trajectory when the source has one (a recorded sequence may).
  virtual const std::optional<Trajectory>& ground_truth() const = 0;

  virtual FrameSourceStats stats() const = 0;

  // A camera: frames arrive whether or not the run is ready for them (the driver keeps the
  // newest), so the run must not stall on seconds of background work.
  virtual bool live() const { return false; }
};

}  // namespace pspslam
