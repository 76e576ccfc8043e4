#pragma once

#include <opencv2/core.hpp>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "pspslam/core/types.h"
#include "pspslam/semantic/segmenter.h"
#include "pspslam/semantic/semantic_delay.h"
#include "pspslam/semantic/semantic_pace.h"
#include "pspslam/semantic/semantic_params.h"

namespace pspslam {

// What the semantic thread publishes for one frame.
struct SemanticResult {
  std::int64_t frame_id = 0;
  Timestamp timestamp = 0.0;
  LabelMap labels;          // CV_8UC1 class ids, image size
  cv::Mat dynamic_mask;     // CV_8UC1, 255 = dynamic class (dilated by mask_dilation_px)
  double latency_ms = 0;    // from submit() to publication (queueing + inference)
  double inference_ms = 0;  // includes an injected delay (SemanticParams::injected_delay)
  int level = 0;            // the SemanticPace level it was made at (0 without a pace)
};

struct SemanticStats {
  std::int64_t submitted = 0;
  std::int64_t processed = 0;
  std::int64_t dropped = 0;  // replaced by a newer frame before they were started, or failed
  std::int64_t failed = 0;   // segment() threw: nothing published for that frame
  std::string last_error;    // what() of the last failure
  // With a pace: results published at each level, and how often the level changed.
  std::vector<std::int64_t> processed_per_level;
  int level_changes = 0;
  int level = 0;  // the level in use now
};

// Runs a Segmenter on its own thread (paper Fig. 1: the semantic thread beside tracking).
// submit() never waits for inference: frames wait in a bounded queue (params.queue_size) and
// when it is full the oldest pending frame is dropped, so the thread always works on the most
// recent frames. Results are published in increasing frame order and kept (params.history
// newest) for look-up by timestamp. The destructor stops the thread and joins it; frames still
// pending are dropped, an inference under way is finished first.
class SemanticThread {
 public:
  using Clock = std::chrono::steady_clock;

  SemanticThread(std::unique_ptr<Segmenter> segmenter, const SemanticParams& params);
  // Several segmenters (largest input first, the same classes) under a pace that picks which one
  // runs and how sparsely (SemanticPace); without a pace the first one runs on every frame.
  SemanticThread(std::vector<std::unique_ptr<Segmenter>> segmenters, const SemanticParams& params,
                 std::optional<SemanticPace> pace);
  ~SemanticThread();
  SemanticThread(const SemanticThread&) = delete;
  SemanticThread& operator=(const SemanticThread&) = delete;

  // Queues a BGR frame (the Mat is shared, not copied: do not write to it afterwards).
  // Frame ids must increase. Returns false after stop().
  bool submit(std::int64_t frame_id, Timestamp timestamp, const cv::Mat& bgr);

  // Newest published result, or nullptr when none yet.
  std::shared_ptr<const SemanticResult> newest() const;
  // Published result whose timestamp is within `tolerance` seconds of `t` (closest), or nullptr.
  std::shared_ptr<const SemanticResult> find(Timestamp t, double tolerance = 1e-4) const;
  // Waits up to `timeout` for the result of frame `frame_id`; nullptr when it was dropped,
  // the wait timed out, or the thread stopped.
  std::shared_ptr<const SemanticResult> wait_for(std::int64_t frame_id,
                                                 std::chrono::milliseconds timeout) const;
  // Blocks until nothing is pending or running (for tools and tests).
  void wait_idle() const;

  // Stops accepting frames, drops pending ones, finishes the running inference and joins.
  void stop();

  SemanticStats stats() const;
  // Frames the caller should skip between submissions: the pace's stride (1 without a pace).
  int stride() const { return stride_.load(std::memory_order_relaxed); }
  // The pace's level now (0 without a pace).
  int level() const { return level_.load(std::memory_order_relaxed); }

 private:
  struct Pending {
    std::int64_t frame_id = 0;
    Timestamp timestamp = 0.0;
    cv::Mat bgr;
    Clock::time_point submitted{};
  };

  void run();
  // Segments `job` with the level's network (and the injected delay); throws what segment() does.
  void segment(const Pending& job, SemanticResult& result);
  // Publishes a finished result and lets the pace choose the next level.
  void publish(std::shared_ptr<SemanticResult> result);

  std::vector<std::unique_ptr<Segmenter>> segmenters_;
  std::optional<SemanticPace> pace_;  // touched by the worker only, stats under mutex_
  SemanticDelayDraw delay_;
  std::atomic<int> stride_{1};
  std::atomic<int> level_{0};
  std::vector<int> dynamic_ids_;
  int dilation_px_;
  size_t queue_size_;
  size_t history_size_;

  mutable std::mutex mutex_;
  mutable std::condition_variable work_cv_;  // worker waits for frames
  mutable std::condition_variable done_cv_;  // consumers wait for results
  std::deque<Pending> pending_;
  std::deque<std::shared_ptr<const SemanticResult>> history_;
  std::int64_t last_submitted_id_ = std::numeric_limits<std::int64_t>::min();
  std::int64_t last_finished_id_ =
      std::numeric_limits<std::int64_t>::min();  // published or dropped
  bool busy_ = false;
  bool stopping_ = false;
  SemanticStats stats_;
  std::thread worker_;  // last member: starts after everything above is constructed
};

}  // namespace pspslam
