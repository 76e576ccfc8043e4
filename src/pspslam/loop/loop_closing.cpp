#include "pspslam/loop/loop_closing.h"

#include <chrono>

#include "pspslam/core/clock.h"
#include "pspslam/core/thread_priority.h"
#include "pspslam/map/keyframe.h"
#include "pspslam/map/map.h"
#include "pspslam/mapping/local_mapping.h"

namespace pspslam {

void close_loops_with_scale(LoopClosingOptions& options) {
  options.detector.ransac.estimate_scale = true;
  options.detector.ransac_error_base = 0.0;
  options.detector.ransac_error_per_depth = 0.03;
  options.detector.ransac_error_per_depth2 = 0.0;
  options.detector.refine_by_reprojection = true;
  options.correction.pose_graph.optimize_scale = true;
}

LoopClosing::LoopClosing(std::shared_ptr<Map> map, std::shared_ptr<PlaceRecognition> place,
                         LocalMapping* local_mapping, LoopClosingOptions options,
                         std::function<void()> on_map_corrected)
    : map_(std::move(map)),
      place_(std::move(place)),
      local_mapping_(local_mapping),
      options_(std::move(options)),
      on_map_corrected_(std::move(on_map_corrected)),
      detector_(*map_, *place_, options_.detector),
      thread_([this](const std::stop_token& stop) { run(stop); }) {}

LoopClosing::~LoopClosing() {
  thread_.request_stop();
  if (thread_.joinable()) thread_.join();
  stop_global_bundle_adjustment();
}

void LoopClosing::insert_keyframe(std::shared_ptr<KeyFrame> keyframe) {
  {
    std::lock_guard lock(mutex_);
    queue_.push_back(std::move(keyframe));
  }
  wake_.notify_one();
}

void LoopClosing::wait_until_idle() {
  std::unique_lock lock(mutex_);
  idle_.wait(lock, [this] { return queue_.empty() && !busy_ && !global_ba_running_; });
}

LoopClosingStats LoopClosing::stats() const {
  std::lock_guard lock(mutex_);
  LoopClosingStats stats = stats_;
  return stats;
}

void LoopClosing::run(const std::stop_token& stop) {
  lower_this_thread_priority(options_.thread_nice);
  while (!stop.stop_requested()) {
    std::shared_ptr<KeyFrame> keyframe;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, stop, [this] { return !queue_.empty(); });
      if (stop.stop_requested()) break;
      keyframe = std::move(queue_.front());
      queue_.pop_front();
      busy_ = true;
    }
    if (!keyframe->is_bad()) process(keyframe);
    {
      std::lock_guard lock(mutex_);
      busy_ = false;
      stats_.detector = detector_.stats();
    }
    idle_.notify_all();
  }
  std::lock_guard lock(mutex_);
  busy_ = false;
  queue_.clear();
  idle_.notify_all();
}

void LoopClosing::process(const std::shared_ptr<KeyFrame>& keyframe) {
  const auto start = std::chrono::steady_clock::now();
  const auto candidates = detector_.detect(keyframe);
  std::optional<DetectedLoop> loop;
  if (!candidates.empty()) loop = detector_.verify(keyframe, candidates);
  {
    std::lock_guard lock(mutex_);
    stats_.detection_ms_total += milliseconds_since(start);
  }
  if (loop) close_loop(*loop);
}

bool LoopClosing::stop_local_mapping(const std::function<bool()>& abort) {
  if (local_mapping_ == nullptr) return true;
  local_mapping_->request_stop();
  // Local mapping acknowledges between keyframes (a running BA is interrupted): milliseconds.
  while (!local_mapping_->is_stopped()) {
    if (abort && abort()) {
      local_mapping_->release();
      return false;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

void LoopClosing::close_loop(const DetectedLoop& loop) {
  // A global BA from an earlier loop would write back a map this correction invalidates.
  stop_global_bundle_adjustment();
  stop_local_mapping({});
  const LoopCorrectionReport report =
      correct_loop(*map_, loop, loop_edges_, options_.correction, on_map_corrected_);
  detector_.loop_closed_at(loop.current->id());
  {
    std::lock_guard lock(mutex_);
    if (!report.merge) ++stats_.loops_closed;
    stats_.last_correction = report;
  }
  // On the map the loop closed (after a merge: the merged one); other maps are not touched.
  if (options_.global_bundle_adjustment) start_global_bundle_adjustment(loop.matched->map_id());
  if (local_mapping_ != nullptr) local_mapping_->release();
}

void LoopClosing::stop_global_bundle_adjustment() {
  if (!global_ba_thread_.joinable()) return;
  abort_global_ba_ = true;
  global_ba_thread_.join();
  abort_global_ba_ = false;
}

void LoopClosing::start_global_bundle_adjustment(std::uint32_t map_id) {
  {
    std::lock_guard lock(mutex_);
    global_ba_running_ = true;
    ++stats_.global_ba_started;
  }
  global_ba_thread_ = std::jthread([this, map_id] { run_global_bundle_adjustment(map_id); });
}

void LoopClosing::run_global_bundle_adjustment(std::uint32_t map_id) {
  GlobalBaOptions options = options_.global_ba;
  options.map_id = map_id;
  const auto aborted = [this] { return abort_global_ba_.load(); };
  options.should_stop = aborted;
  const GlobalBaResult result = solve_global_bundle_adjustment(*map_, options);
  bool applied = false;
  if (result.completed && !aborted() && stop_local_mapping(aborted)) {
    {
      std::lock_guard lock(map_->update_mutex());
      apply_global_bundle_adjustment(*map_, result);
      if (on_map_corrected_) on_map_corrected_();
    }
    applied = true;
    if (local_mapping_ != nullptr) local_mapping_->release();
  }
  {
    std::lock_guard lock(mutex_);
    (applied ? stats_.global_ba_applied : stats_.global_ba_aborted) += 1;
    stats_.last_global_ba_seconds = result.seconds;
    stats_.last_global_ba_keyframes = result.keyframes;
    stats_.last_global_ba_points = result.points;
    global_ba_running_ = false;
  }
  idle_.notify_all();
}

}  // namespace pspslam
