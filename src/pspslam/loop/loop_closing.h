#pragma once

// Loop closing thread (ORB-SLAM2 LoopClosing) and the global bundle adjustment it starts.
//
//   LoopClosing loop(map, place, local_mapping, options, on_map_corrected);  // thread starts
//   local mapping hands each processed keyframe:  loop.insert_keyframe(keyframe);
//   loop.wait_until_idle();   // offline runs: queue drained and global BA finished
//   // destructor: aborts a running global BA and joins both threads
//
// Per keyframe: detection (BoW + covisibility consistency), verification (3D-3D RANSAC, guided
// matching, projection), and for an accepted loop (or a place in another map of the atlas, which
// merges the two: map_merge.h) the correction: a running global BA is
// aborted, local mapping is stopped, correct_loop() rewrites the map under Map::update_mutex(),
// local mapping is released, and a new global BA starts on its own thread. That global BA works
// on a snapshot and takes the mutex only to write its result back (with local mapping stopped),
// so neither tracking nor the next loop detection waits for it.

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <stop_token>
#include <thread>

#include "pspslam/loop/loop_corrector.h"
#include "pspslam/loop/loop_detector.h"
#include "pspslam/optimize/global_bundle_adjustment.h"

namespace pspslam {

class KeyFrame;
class LocalMapping;
class Map;
class PlaceRecognition;

struct LoopClosingOptions {
  LoopDetectorOptions detector;
  LoopCorrectionOptions correction;
  bool global_bundle_adjustment = true;
  GlobalBaOptions global_ba;
  // Nice increment of the loop closing thread; the global BA threads it starts inherit it
  // (core/thread_priority.h; real-time runs).
  int thread_nice = 0;
};

// Loop closing for a map without a metric unit whose scale drifts (monocular): the loop transform
// is a similarity and the essential graph spreads the scale error too (ORB-SLAM2's Sim3Solver,
// OptimizeSim3 and OptimizeEssentialGraph for monocular). The RANSAC inlier test becomes relative
// to the depth: 3 % of it, about 1.7° seen sideways. The reprojection checks of the refinement
// that follows are in pixels and need no change.
void close_loops_with_scale(LoopClosingOptions& options);

struct LoopClosingStats {
  LoopDetectorStats detector;
  std::uint64_t loops_closed = 0;  // within one map (merges: Map::merges)
  std::uint64_t global_ba_started = 0;
  std::uint64_t global_ba_applied = 0;
  std::uint64_t global_ba_aborted = 0;
  LoopCorrectionReport last_correction;
  double last_global_ba_seconds = 0.0;
  std::size_t last_global_ba_keyframes = 0;
  std::size_t last_global_ba_points = 0;
  double detection_ms_total = 0.0;  // wall time of detection + verification
};

class LoopClosing {
 public:
  // `map`, `place` and `local_mapping` (may be null: nothing to stop) must outlive this object.
  // `on_map_corrected` runs with Map::update_mutex() held after every change of keyframe poses
  // (loop correction, global BA); System uses it to re-anchor the tracker.
  LoopClosing(std::shared_ptr<Map> map, std::shared_ptr<PlaceRecognition> place,
              LocalMapping* local_mapping, LoopClosingOptions options,
              std::function<void()> on_map_corrected);
  ~LoopClosing();
  LoopClosing(const LoopClosing&) = delete;
  LoopClosing& operator=(const LoopClosing&) = delete;

  void insert_keyframe(std::shared_ptr<KeyFrame> keyframe);
  // Blocks until the queue is empty, no keyframe is being processed and no global BA runs.
  void wait_until_idle();
  LoopClosingStats stats() const;

 private:
  void run(const std::stop_token& stop);
  void process(const std::shared_ptr<KeyFrame>& keyframe);
  void close_loop(const DetectedLoop& loop);
  void start_global_bundle_adjustment(std::uint32_t map_id);
  void stop_global_bundle_adjustment();
  void run_global_bundle_adjustment(std::uint32_t map_id);
  // Stops local mapping and waits until it has; false when asked to abort meanwhile.
  bool stop_local_mapping(const std::function<bool()>& abort);

  std::shared_ptr<Map> map_;
  std::shared_ptr<PlaceRecognition> place_;
  LocalMapping* local_mapping_;
  LoopClosingOptions options_;
  std::function<void()> on_map_corrected_;
  LoopDetector detector_;  // used by the loop closing thread only
  LoopEdges loop_edges_;   // loop closing thread only

  mutable std::mutex mutex_;
  std::condition_variable_any wake_;
  std::condition_variable_any idle_;
  std::deque<std::shared_ptr<KeyFrame>> queue_;
  bool busy_ = false;
  bool global_ba_running_ = false;
  LoopClosingStats stats_;

  // Global BA: one thread at a time; a newer loop aborts the running one.
  std::atomic<bool> abort_global_ba_{false};
  std::jthread global_ba_thread_;
  // Last member: starts after everything above exists, joined first.
  std::jthread thread_;
};

}  // namespace pspslam
