#pragma once

#include <memory>
#include <opencv2/core.hpp>

#include "pspslam/config/config.h"
#include "pspslam/core/types.h"
#include "pspslam/tracking/tracker.h"

namespace pspslam {

class LocalMapping;
class Map;
class OrbExtractor;
struct RgbdFrame;
struct RgbdCamera;
struct ScalePyramid;

struct SystemOptions {
  // ORB-SLAM2's virtual stereo baseline for RGB-D (u_r = u - fx * b / z), metres.
  double virtual_baseline = 0.08;
  TrackerOptions tracker;
  // false: keyframes go into the map but no local mapping runs (tests, debugging).
  bool local_mapping = true;
};

// One frame through the system: the tracking result and where the time went.
struct FrameReport {
  TrackResult tracking;
  double extraction_ms = 0.0;
  double tracking_ms = 0.0;
  // CPU time of the calling thread: on a shared, loaded machine wall time includes waiting
  // for a core, CPU time does not.
  double extraction_cpu_ms = 0.0;
  double tracking_cpu_ms = 0.0;
};

struct MappingStats {
  size_t keyframes_in_map = 0;
  size_t map_points = 0;
  size_t queued_keyframes = 0;      // waiting for local mapping now
  size_t max_queued_keyframes = 0;  // over the run: growth means mapping cannot keep up
  size_t processed_keyframes = 0;
  double local_ba_ms_total = 0.0;  // wall time spent in local BA so far
  size_t keyframes_culled = 0;
  size_t points_culled = 0;
  size_t points_triangulated = 0;
  size_t points_fused = 0;
  size_t ba_outliers_removed = 0;
};

// The SLAM system: owns the map, the ORB extractor, the tracker (runs on the caller's thread
// inside track()) and the local mapping thread. The thread layout is in system.cpp.
class System {
 public:
  explicit System(const SystemConfig& config, SystemOptions options = {});
  ~System();
  System(const System&) = delete;
  System& operator=(const System&) = delete;

  // Tracks one frame. `dynamic_mask` (CV_8UC1, non-zero = do not extract features there) may
  // be empty. Uses frame.gray when present, else converts frame.bgr.
  FrameReport track(const RgbdFrame& frame, const cv::Mat& dynamic_mask = {});
  FrameReport track(Timestamp timestamp, const cv::Mat& gray, const cv::Mat& depth_metres,
                    const cv::Mat& dynamic_mask = {});

  // Lets local mapping finish its queue, then stops its thread. Idempotent.
  void shutdown();

  // Keyframe poses (T_world_camera), by keyframe id.
  Trajectory keyframe_trajectory() const;
  // All tracked frames, re-expressed through their BA-refined reference keyframes (see
  // Tracker::refined_trajectory); call after shutdown().
  Trajectory refined_trajectory() const { return tracker_->refined_trajectory(); }
  MappingStats mapping_stats() const;
  const Map& map() const { return *map_; }

 private:
  class MappingConnection;

  std::shared_ptr<const RgbdCamera> camera_;
  std::shared_ptr<const ScalePyramid> pyramid_;
  std::unique_ptr<OrbExtractor> extractor_;
  // Shared with the local mapping thread, which needs the map for as long as it runs.
  std::shared_ptr<Map> map_;
  // Declared before tracker_ so it is destroyed after it (the tracker points to it).
  std::unique_ptr<MappingConnection> mapping_;
  std::unique_ptr<Tracker> tracker_;
  std::uint64_t next_frame_id_ = 0;
};

}  // namespace pspslam
