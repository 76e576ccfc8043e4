#pragma once

#include <chrono>
#include <cstddef>
#include <optional>
#include <string>

#include "pspslam/io/frame_source.h"
#include "pspslam/io/sequence_setup.h"

namespace pspslam {

// A recorded sequence as a FrameSource. Deterministic by default: every frame, in order.
// `paced` feeds it like a live camera (`pspslam run --realtime`): frames are due at their
// timestamps from the first next() on, and next() skips to the newest frame whose time has come
// (the skipped ones count as dropped), sleeping when the caller is early.
class SequenceSource final : public FrameSource {
 public:
  // `max_frames` 0 = all.
  SequenceSource(SequenceSetup setup, size_t max_frames, bool paced);

  std::optional<RgbdFrame> next() override;
  std::optional<size_t> frame_count() const override { return frames_; }
  std::string name() const override { return setup_.sequence.directory().string(); }
  std::string describe() const override { return describe_sequence(setup_); }
  const std::optional<Trajectory>& ground_truth() const override {
    return setup_.sequence.ground_truth();
  }
  FrameSourceStats stats() const override {
    FrameSourceStats stats;
    stats.dropped = dropped_;
    return stats;
  }

  const SequenceSetup& setup() const { return setup_; }

 private:
  SequenceSetup setup_;
  size_t frames_ = 0;
  bool paced_ = false;
  size_t next_index_ = 0;
  size_t dropped_ = 0;
  std::optional<std::chrono::steady_clock::time_point> start_;
};

}  // namespace pspslam
