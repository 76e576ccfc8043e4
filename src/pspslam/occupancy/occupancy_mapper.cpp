#include "pspslam/occupancy/occupancy_mapper.h"

#include <chrono>

#include "pspslam/core/thread_cpu_time.h"
#include "pspslam/core/thread_priority.h"
#include "pspslam/map/keyframe.h"

namespace pspslam {
namespace {

constexpr int kBackgroundNiceIncrement = 10;

double elapsed_ms(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace

OccupancyMapper::OccupancyMapper(PinholeCamera camera, OccupancyOptions options)
    : camera_(std::move(camera)), options_(options), map_(options_) {
  options_.validate();
  thread_ = std::thread([this] { work(); });
}

OccupancyMapper::~OccupancyMapper() {
  {
    std::lock_guard lock(queue_mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void OccupancyMapper::add_keyframe(std::shared_ptr<const KeyFrame> keyframe, const cv::Mat& depth,
                                   const cv::Mat& dynamic_mask) {
  if (!keyframe || depth.empty()) return;
  {
    std::lock_guard lock(queue_mutex_);
    queue_.push_back({std::move(keyframe), depth, dynamic_mask});
  }
  wake_.notify_one();
}

void OccupancyMapper::work() {
  lower_this_thread_priority(kBackgroundNiceIncrement);
  for (;;) {
    std::deque<Pending> batch;
    {
      std::unique_lock lock(queue_mutex_);
      wake_.wait(lock, [this] { return stop_ || !queue_.empty(); });
      if (queue_.empty() && stop_) return;
      batch.swap(queue_);
    }
    std::vector<Entry> scanned;
    for (Pending& pending : batch) {
      Entry& entry = scanned.emplace_back();
      entry.scan = make_keyframe_scan(pending.keyframe->id(), camera_, pending.depth, pending.mask,
                                      options_);
      entry.keyframe = std::move(pending.keyframe);
    }
    std::lock_guard lock(map_mutex_);
    for (Entry& entry : scanned) entries_.push_back(std::move(entry));
    insert_ready(false);
    if (moved_since_insertion()) {
      rebuild(stats_.rebuild_ms_total);
      ++stats_.live_rebuilds;
    }
  }
}

void OccupancyMapper::insert_ready(bool all) {
  const size_t delay = all ? 0 : static_cast<size_t>(options_.insert_delay_keyframes);
  for (size_t i = 0; i + delay < entries_.size(); ++i) {
    Entry& entry = entries_[i];
    if (entry.inserted) continue;
    const auto start = std::chrono::steady_clock::now();
    const double cpu_start = thread_cpu_ms();
    entry.T_world_camera_inserted = entry.keyframe->T_world_camera();
    map_.insert(entry.scan, entry.T_world_camera_inserted);
    entry.inserted = true;
    stats_.insert_ms_total += elapsed_ms(start);
    stats_.insert_cpu_ms_total += thread_cpu_ms() - cpu_start;
    ++stats_.inserted;
  }
}

// Whether an inserted keyframe's pose moved so that its points land half a voxel away at the
// maximum range.
bool OccupancyMapper::moved_since_insertion() const {
  const double limit = options_.resolution_m / 2.0;
  for (const Entry& entry : entries_) {
    if (!entry.inserted || entry.keyframe->is_bad()) continue;
    const Pose delta = entry.T_world_camera_inserted.inverse() * entry.keyframe->T_world_camera();
    const double angle = Eigen::AngleAxisd(delta.linear()).angle();
    if (delta.translation().norm() + angle * options_.max_range_m > limit) return true;
  }
  return false;
}

void OccupancyMapper::rebuild(double& milliseconds) {
  const auto start = std::chrono::steady_clock::now();
  map_.clear();
  for (Entry& entry : entries_) {
    if (!entry.inserted) continue;
    entry.T_world_camera_inserted = entry.keyframe->T_world_camera();
    map_.insert(entry.scan, entry.T_world_camera_inserted);
  }
  milliseconds += elapsed_ms(start);
}

void OccupancyMapper::finish() {
  {
    std::lock_guard lock(queue_mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
  std::lock_guard lock(map_mutex_);
  for (Entry& entry : entries_) entry.inserted = true;
  rebuild(stats_.final_rebuild_ms);
}

void OccupancyMapper::read(const std::function<void(const OccupancyMap&)>& read) const {
  std::lock_guard lock(map_mutex_);
  read(map_);
}

OccupancyStats OccupancyMapper::stats() const {
  std::lock_guard lock(map_mutex_);
  OccupancyStats stats = stats_;
  stats.keyframes = entries_.size();
  stats.map_bytes = map_.memory_bytes();
  for (const Entry& entry : entries_)
    stats.scan_bytes += entry.scan.points.size() * sizeof(Eigen::Vector3f) + sizeof(Entry);
  return stats;
}

std::vector<Eigen::Vector3d> OccupancyMapper::camera_centres() const {
  std::lock_guard lock(map_mutex_);
  std::vector<Eigen::Vector3d> centres;
  for (const Entry& entry : entries_) centres.push_back(entry.keyframe->camera_center());
  return centres;
}

std::vector<Eigen::Vector3d> OccupancyMapper::seen_through() const {
  std::lock_guard lock(map_mutex_);
  std::vector<std::pair<const KeyframeScan*, Pose>> scans;
  for (const Entry& entry : entries_)
    if (entry.inserted) scans.emplace_back(&entry.scan, entry.T_world_camera_inserted);
  return map_.seen_through(scans);
}

}  // namespace pspslam
