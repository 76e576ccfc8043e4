#include "pspslam/semantic/semantic_thread.h"

#include <algorithm>
#include <cmath>

#include "pspslam/core/clock.h"
#include "pspslam/core/error.h"
#include "pspslam/core/thread_priority.h"

namespace pspslam {
namespace {

std::vector<std::unique_ptr<Segmenter>> one_segmenter(std::unique_ptr<Segmenter> segmenter) {
  std::vector<std::unique_ptr<Segmenter>> segmenters;
  segmenters.push_back(std::move(segmenter));
  return segmenters;
}

}  // namespace

SemanticThread::SemanticThread(std::unique_ptr<Segmenter> segmenter, const SemanticParams& params)
    : SemanticThread(one_segmenter(std::move(segmenter)), params, std::nullopt) {}

SemanticThread::SemanticThread(std::vector<std::unique_ptr<Segmenter>> segmenters,
                               const SemanticParams& params, std::optional<SemanticPace> pace)
    : segmenters_(std::move(segmenters)),
      pace_(std::move(pace)),
      delay_(params.injected_delay),
      dilation_px_(params.mask_dilation_px),
      queue_size_(static_cast<size_t>(std::max(1, params.queue_size))),
      history_size_(static_cast<size_t>(std::max(1, params.history))) {
  if (segmenters_.empty() || !segmenters_.front())
    throw Error("SemanticThread: no segmenter given");
  const Segmenter& first = *segmenters_.front();
  for (const auto& segmenter : segmenters_) {
    if (!segmenter || segmenter->class_names() != first.class_names())
      throw Error("SemanticThread: the segmenters of one thread must have the same classes");
  }
  if (pace_) {
    for (const PaceLevel& level : pace_->levels()) {
      if (static_cast<size_t>(level.network) >= segmenters_.size())
        throw Error("SemanticThread: a pace level names a segmenter that was not given");
    }
    stats_.processed_per_level.assign(pace_->levels().size(), 0);
    stride_ = pace_->current().stride;
  }
  dynamic_ids_ =
      params.dynamic_classes.empty()
          ? first.default_dynamic_classes()
          : class_ids(first.class_names(), params.dynamic_classes, "semantic.dynamic_classes");
  worker_ = std::thread([this, nice = params.thread_nice] {
    lower_this_thread_priority(nice);
    run();
  });
}

SemanticThread::~SemanticThread() { stop(); }

void SemanticThread::stop() {
  {
    std::lock_guard lock(mutex_);
    if (stopping_ && !worker_.joinable()) return;
    stopping_ = true;
    stats_.dropped += static_cast<std::int64_t>(pending_.size());
    if (!pending_.empty())
      last_finished_id_ = std::max(last_finished_id_, pending_.back().frame_id);
    pending_.clear();
  }
  work_cv_.notify_all();
  done_cv_.notify_all();
  if (worker_.joinable() && worker_.get_id() != std::this_thread::get_id()) worker_.join();
}

bool SemanticThread::submit(std::int64_t frame_id, Timestamp timestamp, const cv::Mat& bgr) {
  {
    std::lock_guard lock(mutex_);
    if (stopping_) return false;
    if (frame_id <= last_submitted_id_) {
      throw Error("SemanticThread::submit: frame id " + std::to_string(frame_id) +
                  " is not greater than the previous one (" + std::to_string(last_submitted_id_) +
                  ")");
    }
    last_submitted_id_ = frame_id;
    ++stats_.submitted;
    // Latest-frame policy: the producer never waits; the oldest pending frame makes room.
    while (pending_.size() >= queue_size_) {
      last_finished_id_ = std::max(last_finished_id_, pending_.front().frame_id);
      pending_.pop_front();
      ++stats_.dropped;
    }
    pending_.push_back(Pending{frame_id, timestamp, bgr, Clock::now()});
  }
  work_cv_.notify_one();
  done_cv_.notify_all();  // waiters on a dropped frame can give up now
  return true;
}

void SemanticThread::run() {
  for (;;) {
    Pending job;
    {
      std::unique_lock lock(mutex_);
      work_cv_.wait(lock, [this] { return stopping_ || !pending_.empty(); });
      if (stopping_) return;
      job = std::move(pending_.front());
      pending_.pop_front();
      busy_ = true;
    }
    auto result = std::make_shared<SemanticResult>();
    try {
      segment(job, *result);
    } catch (const std::exception& e) {
      // A failing frame must not end the thread: nothing is published for it (consumers
      // waiting for it are released), and the failure is counted and kept for stats().
      std::lock_guard lock(mutex_);
      busy_ = false;
      ++stats_.dropped;
      ++stats_.failed;
      stats_.last_error = e.what();
      last_finished_id_ = std::max(last_finished_id_, job.frame_id);
      done_cv_.notify_all();
      continue;
    }
    result->latency_ms = milliseconds_since(job.submitted);
    publish(std::move(result));
  }
}

void SemanticThread::segment(const Pending& job, SemanticResult& result) {
  result.frame_id = job.frame_id;
  result.timestamp = job.timestamp;
  result.level = pace_ ? pace_->level() : 0;
  Segmenter& segmenter =
      *segmenters_[pace_ ? static_cast<size_t>(pace_->current().network) : size_t{0}];
  const auto t0 = Clock::now();
  result.labels = segmenter.segment(job.bgr);
  result.dynamic_mask = dynamic_mask(result.labels, dynamic_ids_, dilation_px_);
  const std::chrono::milliseconds injected = delay_.next();
  if (injected.count() > 0) std::this_thread::sleep_for(injected);
  result.inference_ms = milliseconds_since(t0);
}

void SemanticThread::publish(std::shared_ptr<SemanticResult> result) {
  if (pace_) {
    pace_->observe(result->inference_ms);
    stride_.store(pace_->current().stride, std::memory_order_relaxed);
    level_.store(pace_->level(), std::memory_order_relaxed);
  }
  {
    std::lock_guard lock(mutex_);
    if (pace_) {
      ++stats_.processed_per_level[static_cast<size_t>(result->level)];
      stats_.level_changes = pace_->changes();
      stats_.level = pace_->level();
    }
    last_finished_id_ = std::max(last_finished_id_, result->frame_id);
    history_.push_back(std::move(result));
    while (history_.size() > history_size_) history_.pop_front();
    ++stats_.processed;
    busy_ = false;
  }
  done_cv_.notify_all();
}

std::shared_ptr<const SemanticResult> SemanticThread::newest() const {
  std::lock_guard lock(mutex_);
  return history_.empty() ? nullptr : history_.back();
}

std::shared_ptr<const SemanticResult> SemanticThread::find(Timestamp t, double tolerance) const {
  std::lock_guard lock(mutex_);
  std::shared_ptr<const SemanticResult> best;
  double best_diff = tolerance;
  for (const auto& r : history_) {
    const double diff = std::abs(r->timestamp - t);
    if (diff <= best_diff) {
      best = r;
      best_diff = diff;
    }
  }
  return best;
}

std::shared_ptr<const SemanticResult> SemanticThread::wait_for(
    std::int64_t frame_id, std::chrono::milliseconds timeout) const {
  std::unique_lock lock(mutex_);
  done_cv_.wait_for(lock, timeout, [&] { return stopping_ || last_finished_id_ >= frame_id; });
  for (auto it = history_.rbegin(); it != history_.rend(); ++it) {
    if ((*it)->frame_id == frame_id) return *it;
    if ((*it)->frame_id < frame_id) break;
  }
  return nullptr;
}

void SemanticThread::wait_idle() const {
  std::unique_lock lock(mutex_);
  done_cv_.wait(lock, [this] { return stopping_ || (pending_.empty() && !busy_); });
}

SemanticStats SemanticThread::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

}  // namespace pspslam
