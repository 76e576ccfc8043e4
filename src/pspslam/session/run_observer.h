#pragma once

#include <cstddef>

#include "pspslam/camera/pinhole_camera.h"
#include "pspslam/core/types.h"
#include "pspslam/session/run_statistics.h"
#include "pspslam/system/system.h"

namespace pspslam {

struct InputFrame;
class OccupancyRun;

// One processed frame as a watcher of the run sees it, on the run loop's thread; everything is
// valid only during RunObserver::frame_done().
struct FrameView {
  const InputFrame& frame;
  const FrameReport& report;
  const System& system;
  const RunStatistics& statistics;
  const MappingStats& mapping;
  const Trajectory& estimate;  // every pose computed so far
  size_t frames_total = 0;     // 0: unknown (a live camera)
  // The intrinsics the frame was tracked with (people are placed on the frame through them);
  // null when unknown.
  const PinholeCamera* camera = nullptr;
  // --occupancy: the map being built (thread-safe to read); valid until run_ended() returns.
  const OccupancyRun* occupancy = nullptr;
};

// Someone watching a run as it goes (the live viewer, viewer/live_viewer.h). Called on the run
// loop's thread, so whatever it does there is time the frames wait: take what is needed and
// hand the work to a thread of its own.
class RunObserver {
 public:
  virtual ~RunObserver() = default;
  // What the observer wants recorded for the next frame.
  struct Detail {
    // Keypoint fates, tested points and grown regions: only for the frames that will be shown.
    bool fates = false;
    // With fates, also the keypoints the semantic mask kept from being extracted: they cost a
    // second, unmasked ORB extraction on the run loop's thread.
    bool masked_keypoints = false;
  };
  // Asked before each frame.
  virtual Detail wants_detail() = 0;
  // After each frame. May block (a paused viewer) until the loop may go on; it must return
  // once interrupted() is true.
  virtual void frame_done(const FrameView& view) = 0;
  // The frame loop is over (end of the frames, interrupt, error): nothing waits any more.
  virtual void run_ended() = 0;
};

}  // namespace pspslam
