// Thread layout of the SLAM system:
//
//   caller thread           System::track(): ORB extraction -> Frame -> Tracker::track()
//                             (holds Map::update_mutex() while it works on one frame)
//                                  | KeyFrameSink::insert_keyframe (keyframe already in Map)
//                                  v
//   local mapping thread    LocalMapping (mapping/): queue of keyframes; per keyframe point
//                             culling, triangulation, fusion, local BA, keyframe culling; it
//                             takes Map::update_mutex() while it writes BA results back
//
// Later issues add the semantic and geometry threads in front of tracking (they produce the
// dynamic mask passed to track()).
#include "pspslam/system/system.h"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <mutex>
#include <opencv2/imgproc.hpp>

#include "pspslam/feature/orb_extractor.h"
#include "pspslam/io/rgbd_sequence.h"
#include "pspslam/map/frame.h"
#include "pspslam/map/keyframe.h"
#include "pspslam/map/map.h"
#include "pspslam/map/rgbd_camera.h"
#include "pspslam/map/scale_pyramid.h"
#include "pspslam/mapping/local_mapping.h"
#include "pspslam/tracking/keyframe_sink.h"

namespace pspslam {
namespace {

double thread_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
}

double milliseconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace

// Connects tracking's KeyFrameSink to the local mapping thread (or to nothing when local
// mapping is off: keyframes are then complete in the map, just never refined) and keeps the
// run statistics that LocalMapping does not (queue high-water mark, BA time).
class System::MappingConnection final : public KeyFrameSink {
 public:
  explicit MappingConnection(std::unique_ptr<LocalMapping> mapping)
      : mapping_(std::move(mapping)) {}

  void insert_keyframe(std::shared_ptr<KeyFrame> keyframe) override {
    if (!mapping_) return;
    mapping_->insert_keyframe(std::move(keyframe));
    std::lock_guard lock(mutex_);
    max_queue_ = std::max(max_queue_, mapping_->queue_size());
  }
  bool accepts_keyframes() const override { return !mapping_ || mapping_->accepts_keyframes(); }
  size_t queued_keyframes() const override { return mapping_ ? mapping_->queue_size() : 0; }
  void interrupt_bundle_adjustment() override {
    if (mapping_) mapping_->interrupt_bundle_adjustment();
  }

  // Drains the queue (so the final map includes every keyframe), then joins the thread.
  void stop() {
    if (!mapping_) return;
    mapping_->wait_until_idle();
    poll();
    mapping_.reset();
  }

  void fill(MappingStats& stats) {
    poll();
    std::lock_guard lock(mutex_);
    stats.queued_keyframes = mapping_ ? mapping_->queue_size() : 0;
    stats.max_queued_keyframes = max_queue_;
    stats.processed_keyframes = processed_;
    stats.local_ba_ms_total = ba_ms_total_;
    stats.keyframes_culled = last_.keyframes_culled;
    stats.points_culled = last_.points_culled;
    stats.points_triangulated = last_.points_triangulated;
    stats.points_fused = last_.points_fused;
    stats.ba_outliers_removed = last_.ba_outliers_removed;
  }

 private:
  // LocalMapping reports the duration of the last BA; summed here once per new BA. Polled at
  // every frame, which is more often than keyframes (and so BAs) complete.
  void poll() {
    if (!mapping_) return;
    const LocalMappingStats stats = mapping_->stats();
    std::lock_guard lock(mutex_);
    if (stats.bundle_adjustments > bundle_adjustments_seen_) {
      ba_ms_total_ += 1000.0 * stats.last_bundle_adjustment_seconds *
                      static_cast<double>(stats.bundle_adjustments - bundle_adjustments_seen_);
      bundle_adjustments_seen_ = stats.bundle_adjustments;
    }
    processed_ = stats.keyframes_processed;
    last_ = stats;
  }

  std::unique_ptr<LocalMapping> mapping_;
  std::mutex mutex_;
  size_t max_queue_ = 0;
  size_t processed_ = 0;
  std::uint64_t bundle_adjustments_seen_ = 0;
  double ba_ms_total_ = 0.0;
  LocalMappingStats last_;
};

System::System(const SystemConfig& config, SystemOptions options)
    : camera_(std::make_shared<const RgbdCamera>(
          RgbdCamera::from_config(config.camera, options.virtual_baseline))),
      pyramid_(std::make_shared<const ScalePyramid>(ScalePyramid::from_config(config.orb))),
      extractor_(std::make_unique<OrbExtractor>(config.orb)),
      map_(std::make_shared<Map>()) {
  std::unique_ptr<LocalMapping> mapping;
  if (options.local_mapping) {
    LocalMappingOptions mapping_options;
    mapping_options.close_depth = config.camera.depth_threshold;
    mapping = std::make_unique<LocalMapping>(map_, mapping_options);
  }
  mapping_ = std::make_unique<MappingConnection>(std::move(mapping));
  // ORB-SLAM2 wants a keyframe at least once per second of video.
  options.tracker.keyframes.max_frames_between = static_cast<int>(config.camera.fps);
  tracker_ = std::make_unique<Tracker>(*map_, mapping_.get(), options.tracker);
}

System::~System() { shutdown(); }

FrameReport System::track(const RgbdFrame& frame, const cv::Mat& dynamic_mask) {
  if (!frame.gray.empty()) return track(frame.timestamp, frame.gray, frame.depth, dynamic_mask);
  cv::Mat gray;
  cv::cvtColor(frame.bgr, gray, cv::COLOR_BGR2GRAY);
  return track(frame.timestamp, gray, frame.depth, dynamic_mask);
}

FrameReport System::track(Timestamp timestamp, const cv::Mat& gray, const cv::Mat& depth_metres,
                          const cv::Mat& dynamic_mask) {
  FrameReport report;
  const auto start = std::chrono::steady_clock::now();
  const double cpu_start = thread_cpu_ms();
  OrbFeatures features;
  extractor_->extract(gray, dynamic_mask, features);
  Frame frame(next_frame_id_++, timestamp, std::move(features.keypoints),
              std::move(features.descriptors), depth_metres, camera_, pyramid_);
  report.extraction_ms = milliseconds_since(start);
  const double cpu_tracking_start = thread_cpu_ms();
  report.extraction_cpu_ms = cpu_tracking_start - cpu_start;
  const auto tracking_start = std::chrono::steady_clock::now();
  report.tracking = tracker_->track(std::move(frame));
  report.tracking_ms = milliseconds_since(tracking_start);
  report.tracking_cpu_ms = thread_cpu_ms() - cpu_tracking_start;
  return report;
}

void System::shutdown() { mapping_->stop(); }

Trajectory System::keyframe_trajectory() const {
  Trajectory trajectory;
  for (const auto& keyframe : map_->keyframes()) {
    trajectory.push_back({keyframe->timestamp(), keyframe->T_world_camera()});
  }
  return trajectory;
}

MappingStats System::mapping_stats() const {
  MappingStats stats;
  stats.keyframes_in_map = map_->num_keyframes();
  stats.map_points = map_->num_map_points();
  mapping_->fill(stats);
  return stats;
}

}  // namespace pspslam
