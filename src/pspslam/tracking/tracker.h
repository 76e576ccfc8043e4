#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "pspslam/core/types.h"
#include "pspslam/map/frame.h"
#include "pspslam/match/orb_matcher.h"
#include "pspslam/optimize/pose_optimizer.h"
#include "pspslam/tracking/frame_pose_optimization.h"
#include "pspslam/tracking/keyframe_policy.h"
#include "pspslam/tracking/local_map.h"
#include "pspslam/tracking/map_initializer.h"
#include "pspslam/tracking/mover_guard.h"
#include "pspslam/tracking/relocalizer.h"

namespace pspslam {

class KeyFrame;
class KeyFrameSink;
class Map;
class PlaceRecognition;
struct TrackedMotion;

struct TrackerOptions {
  int min_initial_depth_points = 500;  // keypoints with depth needed to start the map (RGB-D)
  double motion_search_radius = 7.0;   // pixels at level 0 (ORB-SLAM2 RGB-D)
  int min_motion_matches = 20;         // below: search again with twice the radius
  int min_pose_inliers = 10;           // motion model / reference keyframe success
  int min_reference_matches = 15;
  double local_map_search_radius = 3.0;  // ORB-SLAM2 RGB-D window factor
  int min_local_map_inliers = 30;
  int min_local_map_inliers_after_recovery = 50;
  size_t max_local_keyframes = 80;
  KeyFramePolicyOptions keyframes;
  // Localisation only: track against the existing map, never insert keyframes (so no points
  // or local mapping either). With a loaded map, see Tracker::start_in_loaded_map().
  bool localization_only = false;
  MatcherOptions matcher;
  PoseOptimizerOptions pose_optimizer;
  // A frame tracked with the motion model is optimised with the constant-velocity prediction as a
  // Gaussian prior of these σs (rad, m; 0 = no prior; `pspslam run --motion-prior MM DEG`). Off:
  // the prior lowers the online trajectory's frame-to-frame jitter but not its ATE, and tight σs
  // raise the ATE: it trades jitter for wander.
  double motion_prior_sigma_rotation = 0.0;
  double motion_prior_sigma_translation = 0.0;
  // Rolling-shutter cameras: how far (rad/s) a frame's rotation rate may be from the previous
  // frame's before the image must show it (the prior of optimize/rolling_shutter_pose.h): 0.03
  // rad/s in 33 ms is a hand-held angular acceleration of ~50 deg/s^2. A looser prior lets the
  // weakly seen tilt rate follow noise (docs/decisions/rolling-shutter.md).
  double rotation_rate_sigma = 0.03;
  RelocalizerOptions relocalizer;
  // The atlas (map/map.h): a tracker lost for this long (seconds of the sequence's clock) whose
  // relocalisation in every map failed meanwhile starts a new map, and a monocular map lost while
  // it is too young to relocalise in (MapInitializer::restart_when_lost_below) does so at once
  // and keeps its poses. 0: never; the tracker stays lost until relocalised, and a young
  // monocular map is emptied and started again (TrackResult::restart_due).
  double new_map_after_seconds = 0.0;
  // Hold the motion model's pose when the inliers slide onto a moving cluster (MoverGuard).
  MoverGuardOptions mover_guard;
  // A frame given a judged_through_frame (a live frame on a stale mask) solves its pose on the
  // judged points first (optimize_frame_pose_judged_first); off: on every match
  // (docs/decisions/judged-points-first.md).
  bool judged_points_first = true;
  int min_judged_points = 30;
};

enum class TrackingState { kNotInitialized, kOk, kLost };

// How the frame's pose was first estimated before local map tracking refined it.
// kRelocalisation: BoW relocalisation against the whole map (lost frames, with a vocabulary);
// kRecovery: the older fallback against the last reference keyframe when that fails.
enum class TrackingMethod {
  kNone,
  kInitialization,
  kMotionModel,
  kReferenceKeyFrame,
  kRecovery,
  kRelocalisation
};

const char* to_string(TrackingState state);
const char* to_string(TrackingMethod method);

struct TrackResult {
  std::uint64_t frame_id = 0;
  Timestamp timestamp = 0.0;
  TrackingState state = TrackingState::kNotInitialized;
  TrackingMethod method = TrackingMethod::kNone;
  // Set only when the frame was tracked: a lost frame gets no pose, never an invented one.
  std::optional<Pose> T_world_camera;
  bool keyframe_inserted = false;
  int num_keypoints = 0;
  int num_inliers = 0;  // map point matches after local map tracking
  // Frames before the map exists: keypoints with a depth reading, against the number the first
  // map needs (so a caller can say why a sequence never starts, e.g. empty depth images).
  int keypoints_with_depth = 0;
  int keypoints_with_depth_needed = 0;
  // Monocular, before the map exists: matches with the initialiser's reference frame and the
  // two-view model tried on them (none: no attempt).
  int initialization_matches = 0;
  TwoViewModel initialization_model = TwoViewModel::none;
  // The frame that started the map (method kInitialization): earlier frames the new map placed
  // (MapInitializer::take_earlier_frames; monocular: the pair's first frame and the frames
  // between), oldest first, T_world_camera. They had no pose when they were processed.
  std::vector<StampedPose> earlier_frames;
  // Tracking was lost while the map was this young (MapInitializer::restart_when_lost_below):
  // the caller stops local mapping's work and calls Tracker::restart().
  bool restart_due = false;
  // The pose is the motion model's prediction: the optimised one followed a moving cluster
  // (MoverGuard).
  bool pose_held = false;
  // Matches to points made since the frame given as judged_through_frame that the pose did not
  // use: they disagreed with the pose the judged points gave (TrackerOptions::judged_points_first).
  int unjudged_matches_set_aside = 0;
  // The map of the atlas the pose is in (Map::active_map), as it was when the frame was tracked.
  std::uint32_t map_id = 0;
  // The frame started a map while others existed (TrackerOptions::new_map_after_seconds).
  bool new_map = false;
};

// Tracking of each frame (ORB-SLAM2 semantics): map initialisation by the sensor's
// MapInitializer (the first frame with enough depth, or two monocular views), constant-velocity
// motion model, reference-keyframe fallback, local map tracking, keyframe decision. When
// tracking fails the frame is reported lost and the next frames are relocalised against the
// whole atlas through the keyframe database (Relocalizer, when a PlaceRecognition is given), else /
// then against the last reference keyframe (PnP-RANSAC from brute-force matches, since the last
// pose may be stale). With TrackerOptions::new_map_after_seconds, a tracker that stays lost
// starts a new map in the atlas, and while it starts it every frame is first relocalised in the
// maps there are (a return to a known place joins that map instead). Without it no new map is
// started, so all poses stay in one world frame, except that a monocular map lost while it has
// at most MapInitializer::restart_when_lost_below() keyframes is restarted
// (TrackResult::restart_due).
//
// Not thread-safe: one thread calls track(). It holds map.update_mutex() while it works on a
// frame, so local mapping cannot rewrite poses or points under it.
class Tracker {
 public:
  // `map` and `sink` must outlive the tracker; `sink` may be null (no local mapping); `place`
  // may be null (no relocalisation through the keyframe database). `initializer`: how the map
  // starts (the sensor's, system/frame_builder.h); null: from depth, one frame with
  // options.min_initial_depth_points keypoints with depth.
  Tracker(Map& map, KeyFrameSink* sink, TrackerOptions options = {},
          std::shared_ptr<PlaceRecognition> place = nullptr,
          std::unique_ptr<MapInitializer> initializer = nullptr);
  ~Tracker();

  // `judged_through_frame`: the map points made by this frame's keyframes and older ones have
  // been judged by an exact semantic mask, newer ones not yet (a live run's stale mask); see
  // TrackerOptions::judged_points_first.
  TrackResult track(Frame frame, std::optional<std::uint64_t> judged_through_frame = std::nullopt);

  // Every tracked frame moved by the corrections mapping has since applied to the keyframes
  // around it in time, never across a loop correction or global BA
  // (refine_by_keyframe_corrections; culled keyframes give none). Lost frames are absent, as in
  // track(). Call when local mapping is idle or stopped.
  Trajectory refined_trajectory() const;
  // Per pose of refined_trajectory(), the map of the atlas it is in now (after the merges).
  std::vector<std::uint32_t> refined_map_ids() const;

  // Keyframe poses were corrected behind the tracker's back (loop closing, global BA): the last
  // tracked pose is re-expressed through its reference keyframe, as ORB-SLAM2 does, so that the
  // motion model predicts the next frame in the corrected map. The caller holds
  // Map::update_mutex() (so this never runs inside track()).
  void on_map_corrected();
  // The latest tracked pose (T_world_camera), corrected like the tracker's own state.
  std::optional<Pose> last_tracked_world_pose() const;
  // The camera's rotation rate (rad/s, in its own frame) that a rolling-shutter camera's last
  // tracked frame was measured to turn at (optimize/rolling_shutter_pose.h); zero for a global
  // shutter, before the first tracked frame and after a lost one. The next frame's keypoints are
  // moved with it (the motion model's assumption; camera/rolling_shutter.h).
  const Eigen::Vector3d& angular_velocity() const { return angular_velocity_; }
  // The frame track() handled last (its map_points: the matches kept after pose optimisation,
  // outliers cleared); null before the first.
  const Frame* last_frame() const { return last_frame_ ? &*last_frame_ : nullptr; }

  // The map was loaded from a file: the first frame is relocalised in it instead of starting a
  // new map. Call before the first track(). Throws pspslam::Error without a PlaceRecognition
  // (nothing else can find the camera in an existing map) or with an empty map.
  void start_in_loaded_map();

  // Forgets the map the tracker knew (after TrackResult::restart_due; the caller has emptied the
  // map and local mapping's queue): the next frames start a new map. Frames tracked before stay
  // out of refined_trajectory(), since the new map has its own world frame (and scale).
  void restart();
  int restarts() const { return restarts_; }

  TrackingState state() const { return state_; }
  const TrackerOptions& options() const { return options_; }

 private:
  bool initialize(Frame& frame, TrackResult& result);
  // initialize(), and the frame's result when it starts the map.
  bool start_map(Frame& frame, TrackResult& result);
  // The tracked frame's last steps: rolling-shutter rate, inliers, movers, keyframe decision.
  void finish_tracked_frame(Frame& frame, TrackResult& result);
  // While a new map is starting: the frame relocalised in the atlas's maps instead.
  bool relocalize_in_atlas(Frame& frame);
  // Lost and relocalisation failed: a new map when it is due (TrackerOptions).
  void on_lost(Frame& frame, TrackResult& result);
  // Forgets the frame-to-frame state (not the frames tracked so far), and the initialiser's
  // frames unless `keep_initializer`.
  void forget_tracking_state(bool keep_initializer = false);
  bool track_with_motion_model(Frame& frame);
  bool track_reference_keyframe(Frame& frame, bool recovering);
  bool relocalize(Frame& frame);
  bool track_local_map(Frame& frame);
  void maybe_insert_keyframe(Frame& frame, TrackResult& result);
  // After a motion-model frame's pose is final: the prediction instead when MoverGuard says so.
  void guard_against_movers(Frame& frame, TrackResult& result);

  // The frame's pose relative to the keyframe made last (else the reference keyframe), with the
  // information tracking has for it: kept by the keyframe made from the frame.
  std::optional<TrackedMotion> tracked_motion(const Frame& frame);
  // Pose-only optimisation of the frame on its current matches; flags outliers, returns inliers.
  int optimize_frame_pose(Frame& frame);
  // Drops outlier matches; returns how many matches with map observations remain.
  static int discard_outliers(Frame& frame);
  void replace_replaced_points(Frame& frame) const;

  Map& map_;
  KeyFrameSink* sink_;
  TrackerOptions options_;
  TrackingState state_ = TrackingState::kNotInitialized;

  std::optional<Frame> last_frame_;  // the previous frame (tracked or not)
  std::optional<Pose> velocity_;     // T_current_last of the last two tracked frames
  // The rotation rate measured on the last tracked frame (rolling shutter only), rad/s.
  Eigen::Vector3d angular_velocity_ = Eigen::Vector3d::Zero();
  // The constant-velocity prediction of the frame being tracked, as a prior for its pose-only
  // optimisations (set only when it was tracked with the motion model and a prior is configured).
  std::optional<PosePrior> motion_prior_;
  // The constant-velocity prediction of the frame being tracked with the motion model.
  std::optional<Pose> predicted_pose_;
  MoverGuard mover_guard_;
  std::optional<std::uint64_t> judged_through_frame_;  // of the frame being tracked
  int unjudged_matches_set_aside_ = 0;                 // by the frame being tracked
  std::optional<Pose> last_tracked_pose_;              // T_camera_world of the latest tracked frame
  std::shared_ptr<KeyFrame> reference_keyframe_;
  std::weak_ptr<KeyFrame> last_keyframe_;  // the keyframe this tracker made last
  std::uint64_t last_keyframe_frame_id_ = 0;
  // The pose information of the frame being tracked from its rolling-shutter refinement (zero for
  // a global shutter or when the refinement gave up).
  PoseInformation rolling_shutter_information_ = PoseInformation::Zero();
  std::uint64_t last_recovery_frame_id_ = 0;
  LocalMap local_map_;
  std::unique_ptr<Relocalizer> relocalizer_;  // null without a vocabulary
  std::unique_ptr<MapInitializer> initializer_;
  int restarts_ = 0;
  std::optional<Timestamp> lost_since_;  // the first frame of the current loss
  bool opening_new_map_ = false;         // a map beyond the first is starting

  struct FrameAnchor {
    Timestamp timestamp = 0.0;
    std::weak_ptr<KeyFrame> reference;
    Pose T_camera_reference;
    Pose T_camera_world;           // as tracked
    bool became_keyframe = false;  // `reference` is the keyframe made from this frame
    int map_epoch = 0;
    std::uint32_t map_id = 0;  // the map of the atlas it was tracked in
  };
  std::vector<FrameAnchor> anchors_;
  int map_epoch_ = 0;  // map corrections and new maps so far

  // Reused per-frame buffers (no allocation per keypoint).
  FramePoseBuffers pose_buffers_;
  std::vector<ProjectedPoint> projected_;
};

}  // namespace pspslam
