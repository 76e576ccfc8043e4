#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <exception>
#include <mutex>
#include <optional>
#include <stop_token>
#include <string>
#include <thread>
#include <vector>

#include "pspslam/core/latest_queue.h"
#include "pspslam/io/frame_source.h"
#include "pspslam/io/sequence_setup.h"

namespace pspslam {

// A recorded sequence as a FrameSource. Deterministic by default: every frame, in order, read by
// next() itself. `paced` feeds it like a live camera (`pspslam run --realtime`): a reader thread
// decodes each frame ahead of its time and delivers it when it is due (its timestamp after the
// first one, counted from the first next()), into a newest-wins slot; next() takes the newest
// delivered frame and waits when the caller is early. A frame the caller did not take before the
// next one was delivered counts as dropped, as does one the reader skipped because it was late
// itself. A frame's `arrival` is its due time: what a camera delivers decoded at that moment, so
// the decoding of the recording's image files, which a camera does not have, is not part of the
// latency measured from it. A paced source may also decode every frame in the constructor, before
// the clock starts (`preload`, `run --preload`), so that the replay puts no decoding on the cores
// while it runs, as a camera would not: `on` does it or refuses (an Error) above kPreloadLimitBytes
// of decoded frames, `automatic` does it up to kAutoPreloadBytes and otherwise decodes on the
// reader thread.
enum class Preload { off, automatic, on };

class SequenceSource final : public FrameSource {
 public:
  static constexpr size_t kPreloadLimitBytes = size_t{8} << 30;
  static constexpr size_t kAutoPreloadBytes = size_t{2} << 30;  // the complete Bonn clip fits

  // Frames `first_frame` .. `first_frame + max_frames - 1` of the sequence (`max_frames` 0 = to
  // the end); each keeps its position in the sequence as InputFrame::index. Throws
  // pspslam::Error when the sequence holds no frame `first_frame`.
  SequenceSource(SequenceSetup setup, size_t max_frames, bool paced, Preload preload = Preload::off,
                 size_t first_frame = 0);
  ~SequenceSource() override;  // stops and joins the reader
  SequenceSource(const SequenceSource&) = delete;
  SequenceSource& operator=(const SequenceSource&) = delete;

  std::optional<InputFrame> next() override;
  std::optional<size_t> frame_count() const override { return frames_; }
  std::string name() const override { return setup_.sequence->directory().string(); }
  std::string describe() const override;
  const std::optional<Trajectory>& ground_truth() const override {
    return setup_.sequence->ground_truth();
  }
  FrameSourceStats stats() const override {
    FrameSourceStats stats;
    stats.dropped = delivered_.dropped() + skipped_.load();
    return stats;
  }

  const SequenceSetup& setup() const { return setup_; }

 private:
  using Clock = std::chrono::steady_clock;
  void read_paced(const std::stop_token& stop);

  SequenceSetup setup_;
  size_t first_ = 0;  // the frames played: [first_, end_) of the sequence
  size_t end_ = 0;
  size_t frames_ = 0;  // end_ - first_
  bool paced_ = false;
  size_t next_index_ = 0;              // deterministic reading
  std::vector<InputFrame> preloaded_;  // --preload: every frame, decoded before the run
  size_t preloaded_bytes_ = 0;
  LatestQueue<InputFrame> delivered_{1};
  std::atomic<size_t> skipped_{0};  // frames the reader never decoded: it was late for them
  std::mutex start_mutex_;
  std::condition_variable_any start_cv_;
  std::optional<Clock::time_point> start_;  // set by the first next(); under start_mutex_
  std::exception_ptr failure_;              // the reader's error, for next(); under start_mutex_
  std::jthread reader_;                     // last: starts after everything above (paced only)
};

}  // namespace pspslam
