#pragma once

#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <opencv2/core.hpp>
#include <optional>
#include <set>
#include <vector>

#include "pspslam/core/types.h"
#include "pspslam/map/camera_model.h"
#include "pspslam/map/feature_grid.h"
#include "pspslam/map/scale_pyramid.h"
#include "pspslam/place/bow_vector.h"

namespace pspslam {

class Frame;
class MapPoint;
class Vocabulary;

// Everything a keyframe is built from besides its id, camera and pyramid: what a map file
// stores (the map point associations and graph links are restored separately).
struct KeyFrameData {
  std::uint64_t frame_id = 0;
  Timestamp timestamp = 0.0;
  Pose T_camera_world = Pose::Identity();
  std::vector<cv::KeyPoint> keypoints;  // undistorted
  cv::Mat descriptors;                  // N x 32 CV_8U
  std::vector<float> depth;             // per keypoint, <= 0: none
};

// What tracking measured when it made a keyframe: its pose relative to the keyframe made before
// it, as the map held that one at the time, and the information of its pose-only optimisation in
// the left update [ω; v] of T_camera_world (optimize/pose_optimizer.h). Bundle adjustment keeps
// it as a relative-pose factor.
struct TrackedMotion {
  std::uint64_t previous_keyframe_id = 0;
  Pose T_camera_previous = Pose::Identity();
  Eigen::Matrix<double, 6, 6> information = Eigen::Matrix<double, 6, 6>::Zero();
};

// A frame kept in the map. Owned by Map; everything it refers to (its map points, covisible
// keyframes, spanning-tree parent and children) is held by weak_ptr, so the Map stays the only
// owner. Pose, associations and connections are guarded separately because tracking reads
// poses while local mapping optimises them.
class KeyFrame : public std::enable_shared_from_this<KeyFrame> {
 public:
  // Copies the frame's features and pose (the frame must have a pose) and its map point
  // associations (non-outlier ones); it does not register itself as an observation.
  KeyFrame(std::uint64_t id, const Frame& frame);
  // Rebuilds a keyframe (map loading): right_u and the feature grid are derived again.
  // Throws pspslam::Error when the per-keypoint arrays disagree in length.
  KeyFrame(std::uint64_t id, KeyFrameData data, std::shared_ptr<const CameraModel> camera,
           std::shared_ptr<const ScalePyramid> pyramid);

  std::uint64_t id() const { return id_; }
  std::uint64_t frame_id() const { return frame_id_; }
  Timestamp timestamp() const { return timestamp_; }

  // --- pose (thread-safe)
  Pose T_camera_world() const;
  Pose T_world_camera() const;
  Eigen::Vector3d camera_center() const;
  void set_pose(const Pose& T_camera_world);

  // --- the atlas (thread-safe): the map this keyframe belongs to (Map's atlas, map.h), and
  // whether it anchors that map: the map's first keyframe, held fixed by bundle adjustment and
  // never culled. A merge relabels the keyframes of the map it brings in, whose anchor stops
  // anchoring.
  std::uint32_t map_id() const { return map_id_.load(std::memory_order_acquire); }
  bool is_anchor() const { return anchor_.load(std::memory_order_acquire); }
  void set_map(std::uint32_t map_id, bool anchor) {
    map_id_.store(map_id, std::memory_order_release);
    anchor_.store(anchor, std::memory_order_release);
  }

  // --- what tracking measured; set once, before the keyframe enters the map (not saved with it)
  void set_tracked_motion(const TrackedMotion& motion) { tracked_motion_ = motion; }
  const std::optional<TrackedMotion>& tracked_motion() const { return tracked_motion_; }

  // --- immutable features
  int size() const { return static_cast<int>(keypoints_.size()); }
  const std::vector<cv::KeyPoint>& keypoints() const { return keypoints_; }
  const cv::Mat& descriptors() const { return descriptors_; }
  const std::uint8_t* descriptor(int i) const { return descriptors_.ptr<std::uint8_t>(i); }
  float depth(int i) const { return depth_[i]; }
  float right_u(int i) const { return right_u_[i]; }  // NaN without depth (see Frame)
  bool has_depth(int i) const { return depth_[i] > 0.0f; }
  const CameraModel& camera() const { return *camera_; }
  const ScalePyramid& pyramid() const { return *pyramid_; }
  void features_in_area(double x, double y, double radius, int min_level, int max_level,
                        std::vector<int>& out) const {
    grid_.query(keypoints_, x, y, radius, min_level, max_level, out);
  }
  Eigen::Vector3d unproject_world(int i) const;  // needs depth(i) > 0

  // --- bag of words (thread-safe). Computed once, by local mapping (off the tracking thread),
  // before the keyframe enters the KeyFrameDatabase; immutable afterwards, so a keyframe found
  // through the database can be read without a lock.
  // Idempotent: a second call (any vocabulary) keeps the first result.
  void compute_bow(const Vocabulary& vocabulary, int direct_index_level);
  bool has_bow() const { return bow_ready_.load(std::memory_order_acquire); }
  // Empty until has_bow(). The feature vector is the direct index at direct_index_level
  // (keypoint indices grouped by vocabulary node) for guided matching.
  const BowVector& bow_vector() const { return has_bow() ? bow_ : no_bow_; }
  const FeatureVector& feature_vector() const { return has_bow() ? features_ : no_features_; }

  // --- map point associations (thread-safe)
  void add_map_point(int index, const std::shared_ptr<MapPoint>& point);
  void erase_map_point(int index);
  void erase_map_point(const MapPoint& point);
  void replace_map_point(int index, const std::shared_ptr<MapPoint>& point);
  std::shared_ptr<MapPoint> map_point(int index) const;  // nullptr if none / expired
  // All associations by keypoint index (nullptr where none or bad).
  std::vector<std::shared_ptr<MapPoint>> map_points() const;
  // Number of good map points with at least `min_observations` observations.
  int tracked_map_points(int min_observations) const;

  // --- covisibility graph (thread-safe). Weight = number of shared map points.
  // Recomputes this keyframe's edges from its map points' observations (edges with >= 15
  // shared points, or the single best one), updates the other side, and on first call sets
  // the spanning-tree parent to the most covisible keyframe.
  void update_connections();
  void add_connection(const std::shared_ptr<KeyFrame>& other, int weight);
  void erase_connection(std::uint64_t other_id);
  int weight(std::uint64_t other_id) const;
  // Covisible keyframes sorted by decreasing weight (all, best n, or weight >= w).
  std::vector<std::shared_ptr<KeyFrame>> covisibles() const;
  std::vector<std::shared_ptr<KeyFrame>> best_covisibles(size_t n) const;
  std::vector<std::shared_ptr<KeyFrame>> covisibles_with_min_weight(int min_weight) const;

  // --- spanning tree (thread-safe)
  std::shared_ptr<KeyFrame> parent() const;
  std::vector<std::shared_ptr<KeyFrame>> children() const;
  void change_parent(const std::shared_ptr<KeyFrame>& parent);
  void add_child(const std::shared_ptr<KeyFrame>& child);
  void erase_child(std::uint64_t child_id);

  // Removes the keyframe from the graph: drops its observations from its map points,
  // its covisibility edges, and re-attaches its children to the spanning tree. A map's anchor
  // is never made bad. The caller erases it from the Map.
  void set_bad();
  bool is_bad() const;

  // Local-map bookkeeping for tracking / mapping (frame or keyframe id that last used it).
  std::uint64_t track_reference_frame = UINT64_MAX;
  std::uint64_t fuse_target_keyframe = UINT64_MAX;
  std::uint64_t local_ba_keyframe = UINT64_MAX;
  std::uint64_t fixed_ba_keyframe = UINT64_MAX;

 private:
  struct Connection {
    std::weak_ptr<KeyFrame> keyframe;
    int weight = 0;
  };
  void update_ordered_connections_locked();

  const std::uint64_t id_;
  const std::uint64_t frame_id_;
  const Timestamp timestamp_;
  const std::vector<cv::KeyPoint> keypoints_;
  const cv::Mat descriptors_;
  const std::vector<float> depth_;
  const std::vector<float> right_u_;
  const std::shared_ptr<const CameraModel> camera_;
  const std::shared_ptr<const ScalePyramid> pyramid_;
  const FeatureGrid grid_;
  std::optional<TrackedMotion> tracked_motion_;
  std::atomic<std::uint32_t> map_id_{0};
  std::atomic<bool> anchor_{false};

  std::mutex bow_mutex_;  // serialises compute_bow; readers use bow_ready_
  std::atomic<bool> bow_ready_{false};
  BowVector bow_;
  FeatureVector features_;
  const BowVector no_bow_;
  const FeatureVector no_features_;

  mutable std::mutex pose_mutex_;
  Pose T_camera_world_;
  Pose T_world_camera_;

  mutable std::mutex features_mutex_;
  std::vector<std::weak_ptr<MapPoint>> map_points_;

  mutable std::mutex connections_mutex_;
  std::map<std::uint64_t, Connection> connections_;
  std::vector<std::pair<int, std::weak_ptr<KeyFrame>>> ordered_connections_;  // by weight desc
  std::weak_ptr<KeyFrame> parent_;
  std::map<std::uint64_t, std::weak_ptr<KeyFrame>> children_;
  bool first_connection_ = true;
  // Atomic so that is_bad() takes no lock: it is called on other keyframes while holding this
  // one's connection mutex, and locking there could deadlock two keyframes against each other.
  std::atomic<bool> bad_{false};
};

}  // namespace pspslam
