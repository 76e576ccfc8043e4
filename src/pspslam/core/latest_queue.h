#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <mutex>
#include <optional>
#include <string>
#include <utility>

namespace pspslam {

// Hands items from a producer that must never wait (a camera driver's callback) to a consumer
// that may be slow (the SLAM loop). Bounded: when it is full, push() discards the oldest item, so
// the consumer always gets the newest frames and the driver never blocks; discarded items are
// counted. close() ends the stream: the consumer still gets what is queued, then nothing.
template <typename T>
class LatestQueue {
 public:
  explicit LatestQueue(size_t capacity) : capacity_(capacity == 0 ? 1 : capacity) {}

  // Never blocks for longer than the consumer holds the lock to move one item out.
  void push(T item) {
    {
      std::lock_guard lock(mutex_);
      if (closed_) return;
      if (items_.size() == capacity_) {
        items_.pop_front();
        ++dropped_;
      }
      items_.push_back(std::move(item));
    }
    ready_.notify_one();
  }

  // The oldest queued item; waits at most `timeout`. nullopt on timeout or when the queue is
  // closed and empty (closed() tells which).
  std::optional<T> pop(std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    ready_.wait_for(lock, timeout, [&] { return !items_.empty() || closed_; });
    if (items_.empty()) return std::nullopt;
    T item = std::move(items_.front());
    items_.pop_front();
    return item;
  }

  // Ends the stream with a reason (kept from the first call).
  void close(std::string reason) {
    {
      std::lock_guard lock(mutex_);
      if (closed_) return;
      closed_ = true;
      reason_ = std::move(reason);
    }
    ready_.notify_all();
  }

  bool closed() const {
    std::lock_guard lock(mutex_);
    return closed_;
  }
  std::string close_reason() const {
    std::lock_guard lock(mutex_);
    return reason_;
  }
  size_t dropped() const {
    std::lock_guard lock(mutex_);
    return dropped_;
  }

 private:
  const size_t capacity_;
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<T> items_;
  size_t dropped_ = 0;
  bool closed_ = false;
  std::string reason_;
};

}  // namespace pspslam
