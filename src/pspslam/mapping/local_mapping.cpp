#include "pspslam/mapping/local_mapping.h"

#include "pspslam/core/thread_priority.h"
#include "pspslam/map/keyframe.h"
#include "pspslam/map/map.h"

namespace pspslam {

LocalMapping::LocalMapping(std::shared_ptr<Map> map, LocalMappingOptions options,
                           std::shared_ptr<PlaceRecognition> place)
    : mapper_(std::move(map), options, std::move(place)),
      thread_([this, nice = options.thread_nice](const std::stop_token& stop) {
        lower_this_thread_priority(nice);
        run(stop);
      }) {}

LocalMapping::~LocalMapping() {
  thread_.request_stop();
  abort_bundle_adjustment_ = true;
  // jthread's destructor joins; wake_ is a condition_variable_any waiting on the stop token.
}

void LocalMapping::insert_keyframe(std::shared_ptr<KeyFrame> keyframe) {
  {
    std::lock_guard lock(mutex_);
    queue_.push_back(std::move(keyframe));
    abort_bundle_adjustment_ = true;
  }
  wake_.notify_one();
}

bool LocalMapping::accepts_keyframes() const {
  std::lock_guard lock(mutex_);
  return !busy_ && !stop_requested_;
}

size_t LocalMapping::queue_size() const {
  std::lock_guard lock(mutex_);
  return queue_.size();
}

void LocalMapping::interrupt_bundle_adjustment() { abort_bundle_adjustment_ = true; }

void LocalMapping::wait_until_idle() {
  std::unique_lock lock(mutex_);
  idle_.wait(lock, [this] { return stopped_ || (!busy_ && queue_.empty()); });
}

void LocalMapping::request_stop() {
  {
    std::lock_guard lock(mutex_);
    stop_requested_ = true;
  }
  abort_bundle_adjustment_ = true;
  wake_.notify_one();
}

bool LocalMapping::is_stopped() const {
  std::lock_guard lock(mutex_);
  return stopped_;
}

void LocalMapping::release() {
  {
    std::lock_guard lock(mutex_);
    stop_requested_ = false;
    stopped_ = false;
  }
  wake_.notify_one();
  idle_.notify_all();
}

void LocalMapping::set_keyframe_listener(
    std::function<void(const std::shared_ptr<KeyFrame>&)> listener) {
  std::lock_guard lock(mutex_);
  listener_ = std::move(listener);
}

LocalMappingStats LocalMapping::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

void LocalMapping::run(const std::stop_token& stop) {
  while (!stop.stop_requested()) {
    std::shared_ptr<KeyFrame> keyframe;
    {
      std::unique_lock lock(mutex_);
      // Wake for a pause to acknowledge, or for work while not paused (or for shutdown).
      wake_.wait(lock, stop, [this] {
        return (stop_requested_ && !stopped_) || (!stop_requested_ && !queue_.empty());
      });
      if (stop.stop_requested()) break;
      if (stop_requested_) {
        stopped_ = true;
        idle_.notify_all();
        continue;
      }
      keyframe = std::move(queue_.front());
      queue_.pop_front();
      busy_ = true;
      abort_bundle_adjustment_ = false;
    }

    const auto has_new_keyframe = [this, &stop] {
      if (abort_bundle_adjustment_ || stop.stop_requested()) return true;
      std::lock_guard lock(mutex_);
      return !queue_.empty() || stop_requested_;
    };
    mapper_.process(keyframe, has_new_keyframe);

    std::function<void(const std::shared_ptr<KeyFrame>&)> listener;
    {
      std::lock_guard lock(mutex_);
      listener = listener_;
    }
    if (listener && !keyframe->is_bad()) listener(keyframe);
    {
      std::lock_guard lock(mutex_);
      busy_ = false;
      stats_ = mapper_.stats();
    }
    idle_.notify_all();
  }
  std::lock_guard lock(mutex_);
  busy_ = false;
  stopped_ = true;
  idle_.notify_all();
}

}  // namespace pspslam
