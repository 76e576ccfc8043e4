#pragma once

#include <Eigen/Core>
#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <vector>

#include "pspslam/map/descriptor.h"

namespace pspslam {

class KeyFrame;
struct ScalePyramid;

// A 3D landmark. Owned by Map; it refers to the keyframes observing it by id + weak_ptr only,
// so there is no ownership cycle with KeyFrame. All accessors are thread-safe (tracking reads
// while local mapping writes).
class MapPoint {
 public:
  struct Observation {
    std::weak_ptr<KeyFrame> keyframe;
    int keypoint_index = -1;
  };

  MapPoint(std::uint64_t id, const Eigen::Vector3d& position_world,
           const std::shared_ptr<KeyFrame>& reference_keyframe);

  std::uint64_t id() const { return id_; }

  Eigen::Vector3d position() const;
  void set_position(const Eigen::Vector3d& position_world);
  Eigen::Vector3d normal() const;  // mean unit viewing direction (point minus camera centre)
  OrbDescriptor descriptor() const;
  // Scale-invariance range: the point can be matched at these camera distances.
  double min_distance() const;
  double max_distance() const;
  std::shared_ptr<KeyFrame> reference_keyframe() const;
  // The frame whose keyframe made the point (0 without one). Unlike the reference keyframe it
  // never changes, so it says how long the point has been in the map.
  std::uint64_t first_frame_id() const { return first_frame_id_; }

  // Observations, keyed by keyframe id. An observation with depth counts twice (as a stereo
  // observation does in ORB-SLAM2) in num_observations().
  void add_observation(const std::shared_ptr<KeyFrame>& keyframe, int keypoint_index);
  // Returns true when the point became bad because too few observations remain.
  bool erase_observation(std::uint64_t keyframe_id);
  std::map<std::uint64_t, Observation> observations() const;
  // Calls fn(keyframe_id, observation) for each observation in keyframe-id order, under the
  // point's lock and without copying them (tracking's hot path); fn must not call back into
  // this point.
  template <typename Fn>
  void for_each_observation(Fn&& fn) const {
    std::lock_guard lock(observation_mutex_);
    for (const auto& [keyframe_id, observation] : observations_) fn(keyframe_id, observation);
  }
  int num_observations() const;
  int keypoint_index_in(std::uint64_t keyframe_id) const;  // -1 if not observed there
  bool is_observed_by(std::uint64_t keyframe_id) const;

  // Recomputes the representative descriptor (the one with least median distance to the
  // others) and the normal / distance range from the current observations.
  void compute_distinctive_descriptor();
  void update_normal_and_depth(const ScalePyramid& pyramid);
  int predict_level(double distance, const ScalePyramid& pyramid) const;

  // Tracking statistics: visible = in a frame's view frustum, found = matched there.
  void increase_visible(int n = 1);
  void increase_found(int n = 1);
  double found_ratio() const;

  // Marks the point bad and detaches it from every keyframe that observed it. The caller
  // removes it from the Map (Map::erase_map_point does both).
  void set_bad();
  bool is_bad() const;
  // Merges this point into `other` (fusion of duplicates): observations move to `other`,
  // this point becomes bad. Returns false if it was already bad.
  bool replace_with(const std::shared_ptr<MapPoint>& other);
  std::shared_ptr<MapPoint> replaced_by() const;

  // Local-map bookkeeping for tracking, to avoid per-frame sets (frame id that last used it).
  std::uint64_t track_reference_frame = UINT64_MAX;
  std::uint64_t last_seen_frame = UINT64_MAX;
  std::uint64_t fuse_candidate_keyframe = UINT64_MAX;
  std::uint64_t first_keyframe_id = 0;

 private:
  const std::uint64_t id_;
  mutable std::mutex position_mutex_;
  Eigen::Vector3d position_;
  Eigen::Vector3d normal_ = Eigen::Vector3d::Zero();
  double min_distance_ = 0.0;
  double max_distance_ = 0.0;

  mutable std::mutex observation_mutex_;
  std::map<std::uint64_t, Observation> observations_;
  int num_observations_ = 0;
  OrbDescriptor descriptor_{};
  std::weak_ptr<KeyFrame> reference_keyframe_;
  const std::uint64_t first_frame_id_;
  std::weak_ptr<MapPoint> replaced_by_;
  int visible_ = 1;
  int found_ = 1;
  std::atomic<bool> bad_{false};  // read lock-free: checked inside keyframe locks
};

}  // namespace pspslam
