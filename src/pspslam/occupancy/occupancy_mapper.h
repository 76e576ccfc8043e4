#pragma once

#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <opencv2/core.hpp>
#include <thread>
#include <vector>

#include "pspslam/camera/pinhole_camera.h"
#include "pspslam/occupancy/occupancy_map.h"
#include "pspslam/occupancy/occupancy_options.h"

namespace pspslam {

class KeyFrame;

struct OccupancyStats {
  size_t keyframes = 0;              // scans kept (one per keyframe)
  size_t inserted = 0;               // scans inserted while the run went
  size_t live_rebuilds = 0;          // rebuilds because inserted keyframes moved
  double insert_ms_total = 0.0;      // incremental insertions (own thread), wall time
  double insert_cpu_ms_total = 0.0;  // the same, CPU time of the thread
  double rebuild_ms_total = 0.0;
  double final_rebuild_ms = 0.0;  // finish(): every scan at its keyframe's final pose
  size_t map_bytes = 0;           // the octree
  size_t scan_bytes = 0;          // the kept scans
};

// Builds the occupancy map of the static scene while the run goes, off the frame path: the
// caller thread only queues each new keyframe with its depth image and dynamic mask; this
// object's thread (below normal priority) turns them into scans and inserts each one once it is
// options.insert_delay_keyframes keyframes old (local BA has refined it by then). When
// inserted keyframes have moved by more than half a voxel (a loop, a merge, global BA), the map
// is rebuilt from the kept scans at their keyframes' current poses: OctoMap's clamped log-odds
// cannot take a scan back out, so re-inserting only what moved would leave the old evidence in.
// finish() rebuilds it once more at the final poses.
class OccupancyMapper {
 public:
  OccupancyMapper(PinholeCamera camera, OccupancyOptions options);
  ~OccupancyMapper();
  OccupancyMapper(const OccupancyMapper&) = delete;
  OccupancyMapper& operator=(const OccupancyMapper&) = delete;

  // Caller thread. `depth` (CV_32F metres) and `dynamic_mask` are shared, not copied: the
  // caller must not write into them afterwards.
  void add_keyframe(std::shared_ptr<const KeyFrame> keyframe, const cv::Mat& depth,
                    const cv::Mat& dynamic_mask);
  // Stops the thread and rebuilds the map from every kept scan at its keyframe's final pose
  // (a culled keyframe at its last one). Call once, after the system has shut down.
  void finish();

  // Runs `read` on the map under its lock (`read` must not call back into this object).
  void read(const std::function<void(const OccupancyMap&)>& read) const;
  OccupancyStats stats() const;
  std::vector<Eigen::Vector3d> camera_centres() const;
  // After finish(): occupied voxels a later keyframe's rays pass through (OccupancyMap).
  std::vector<Eigen::Vector3d> seen_through() const;
  const OccupancyOptions& options() const { return options_; }

 private:
  struct Entry {
    std::shared_ptr<const KeyFrame> keyframe;
    KeyframeScan scan;
    bool inserted = false;
    Pose T_world_camera_inserted = Pose::Identity();
  };
  struct Pending {
    std::shared_ptr<const KeyFrame> keyframe;
    cv::Mat depth, mask;
  };
  void work();
  void insert_ready(bool all);
  bool moved_since_insertion() const;
  void rebuild(double& milliseconds);

  PinholeCamera camera_;
  OccupancyOptions options_;
  mutable std::mutex queue_mutex_;
  std::condition_variable wake_;
  std::deque<Pending> queue_;
  bool stop_ = false;
  mutable std::mutex map_mutex_;  // map_, entries_, stats_
  OccupancyMap map_;
  std::vector<Entry> entries_;
  OccupancyStats stats_;
  std::thread thread_;
};

}  // namespace pspslam
