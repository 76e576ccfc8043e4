#include "pspslam/io/sequence_source.h"

#include <algorithm>
#include <thread>
#include <utility>

namespace pspslam {

SequenceSource::SequenceSource(SequenceSetup setup, size_t max_frames, bool paced)
    : setup_(std::move(setup)),
      frames_(max_frames == 0 ? setup_.sequence.size()
                              : std::min(setup_.sequence.size(), max_frames)),
      paced_(paced) {}

std::optional<RgbdFrame> SequenceSource::next() {
  if (next_index_ >= frames_) return std::nullopt;
  const RgbdSequence& sequence = setup_.sequence;
  if (paced_) {
    // A live camera does not wait: skip to the newest frame whose time has come.
    const auto now = std::chrono::steady_clock::now();
    if (!start_) start_ = now;
    const double elapsed = std::chrono::duration<double>(now - *start_).count();
    const Timestamp t0 = sequence.timestamp(0);
    size_t newest = next_index_;
    while (newest + 1 < frames_ && sequence.timestamp(newest + 1) - t0 <= elapsed) ++newest;
    dropped_ += newest - next_index_;
    next_index_ = newest;
    const double due = sequence.timestamp(newest) - t0;
    const double wait = due - elapsed;
    if (wait > 0) std::this_thread::sleep_for(std::chrono::duration<double>(wait));
    // The frame arrived when it was due, not when the busy caller came for it: the time it
    // waited here is part of its latency, as it is for a camera's buffered frame.
    std::optional<RgbdFrame> frame = sequence.load(next_index_++);
    if (frame) {
      frame->arrival = *start_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                     std::chrono::duration<double>(due));
    }
    return frame;
  }
  return sequence.load(next_index_++);
}

}  // namespace pspslam
