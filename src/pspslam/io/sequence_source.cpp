#include "pspslam/io/sequence_source.h"

#include <algorithm>
#include <exception>
#include <iomanip>
#include <sstream>
#include <utility>

#include "pspslam/core/error.h"

namespace pspslam {

namespace {

size_t frame_bytes(const InputFrame& frame) {
  size_t bytes = 0;
  for (const cv::Mat* image : {&frame.bgr, &frame.depth, &frame.right})
    bytes += image->total() * image->elemSize();
  return bytes;
}

}  // namespace

SequenceSource::SequenceSource(SequenceSetup setup, size_t max_frames, bool paced, Preload preload,
                               size_t first_frame)
    : setup_(std::move(setup)), first_(first_frame), paced_(paced) {
  const size_t size = setup_.sequence->size();
  if (first_ >= size) {
    throw Error("--start-frame " + std::to_string(first_) + ": " +
                setup_.sequence->directory().string() + " holds " + std::to_string(size) +
                " frames (0 .. " + std::to_string(size - 1) + ")");
  }
  end_ = max_frames == 0 ? size : std::min(size, first_ + max_frames);
  frames_ = end_ - first_;
  next_index_ = first_;
  if (preload == Preload::on && !paced_)
    throw Error("--preload: only a --realtime run replays at the camera's rate");
  if (paced_ && preload != Preload::off && frames_ > 0) {
    InputFrame first = setup_.sequence->load(first_);
    const double need = static_cast<double>(frame_bytes(first)) * static_cast<double>(frames_);
    const size_t limit = preload == Preload::on ? kPreloadLimitBytes : kAutoPreloadBytes;
    if (need <= static_cast<double>(limit)) {
      preloaded_.reserve(frames_);
      preloaded_.push_back(std::move(first));
      for (size_t index = first_ + 1; index < end_; ++index)
        preloaded_.push_back(setup_.sequence->load(index));
      preloaded_bytes_ = static_cast<size_t>(need);
    } else if (preload == Preload::on) {
      std::ostringstream message;
      message << std::fixed << std::setprecision(1) << "--preload: " << frames_ << " frames of "
              << setup_.sequence->directory().string() << " decode to "
              << need / static_cast<double>(size_t{1} << 30) << " GiB, more than the "
              << (kPreloadLimitBytes >> 30)
              << " GiB limit; run with --preload off (frames are then decoded ahead on a "
                 "reader thread)";
      throw Error(message.str());
    }
  }
  if (paced_) reader_ = std::jthread([this](const std::stop_token& stop) { read_paced(stop); });
}

SequenceSource::~SequenceSource() {
  reader_.request_stop();
  delivered_.close("source closed");
  // jthread joins; the reader's waits end on the stop token.
}

void SequenceSource::read_paced(const std::stop_token& stop) {
  const RecordedSequence& sequence = *setup_.sequence;
  Clock::time_point start;
  {
    std::unique_lock lock(start_mutex_);
    if (!start_cv_.wait(lock, stop, [this] { return start_.has_value(); })) return;
    start = *start_;
  }
  const Timestamp t0 = frames_ > 0 ? sequence.timestamp(first_) : 0.0;
  try {
    const auto due_time = [&](size_t index) {
      return start + std::chrono::duration_cast<Clock::duration>(
                         std::chrono::duration<double>(sequence.timestamp(index) - t0));
    };
    for (size_t index = first_; index < end_ && !stop.stop_requested(); ++index) {
      // A camera does not queue what it could not deliver: when the reader itself is late
      // (decoding competes for the cores), it goes on with the newest frame already due.
      const auto now = Clock::now();
      size_t newest = index;
      while (newest + 1 < end_ && due_time(newest + 1) <= now) ++newest;
      skipped_ += newest - index;
      index = newest;
      // Decoded ahead, delivered when due; one that is late when decoded is delivered at once,
      // and that lateness counts in its latency (its arrival stays the due time).
      InputFrame frame =
          preloaded_.empty() ? sequence.load(index) : std::move(preloaded_[index - first_]);
      const auto due = due_time(index);
      {
        std::unique_lock lock(start_mutex_);
        start_cv_.wait_until(lock, stop, due, [] { return false; });
      }
      if (stop.stop_requested()) break;
      frame.arrival = due;
      delivered_.push(std::move(frame));
    }
  } catch (...) {
    // An unreadable file ends the feed; next() rethrows it on the caller's thread, which
    // reports it as the deterministic reading would.
    std::lock_guard lock(start_mutex_);
    failure_ = std::current_exception();
  }
  delivered_.close("end of sequence");
}

std::optional<InputFrame> SequenceSource::next() {
  if (!paced_) {
    if (next_index_ >= end_) return std::nullopt;
    return setup_.sequence->load(next_index_++);
  }
  {
    std::lock_guard lock(start_mutex_);
    if (!start_) start_ = Clock::now();
  }
  start_cv_.notify_all();
  for (;;) {
    if (std::optional<InputFrame> frame = delivered_.pop(std::chrono::milliseconds(1000)))
      return frame;
    if (delivered_.closed()) {
      std::lock_guard lock(start_mutex_);
      if (failure_) std::rethrow_exception(std::exchange(failure_, nullptr));
      return std::nullopt;
    }
  }
}

std::string SequenceSource::describe() const {
  std::string text = describe_sequence(setup_);
  if (first_ > 0) {
    text += "start:        frame " + std::to_string(first_) + " (--start-frame; " +
            std::to_string(first_) + " frames skipped)\n";
  }
  if (paced_) {
    std::ostringstream line;
    line << "replay:       paced at the recording's rate; ";
    if (preloaded_.size() == frames_ && frames_ > 0)
      line << std::fixed << std::setprecision(2) << "every frame decoded before the start ("
           << static_cast<double>(preloaded_bytes_) / static_cast<double>(size_t{1} << 30)
           << " GiB, --preload)";
    else
      line << "frames decoded ahead on a reader thread (--preload off or above "
           << (kAutoPreloadBytes >> 30) << " GiB)";
    text += line.str() + "\n";
  }
  return text;
}

}  // namespace pspslam
