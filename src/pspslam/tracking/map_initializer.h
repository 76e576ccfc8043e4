#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include "pspslam/core/types.h"
#include "pspslam/optimize/pose_optimizer.h"
#include "pspslam/solve/two_view_initializer.h"

namespace pspslam {

class Frame;
class KeyFrame;
class Map;

// What the frames before the first map tell about why it has not started yet.
struct InitializationProgress {
  // RGB-D and stereo: keypoints with depth, against the number the first map needs (a caller
  // says why a sequence never starts, e.g. empty depth images). Monocular: both 0.
  int keypoints_with_depth = 0;
  int keypoints_with_depth_needed = 0;
  // Monocular: the two-view attempt on this frame (model none when none was made).
  int initialization_matches = 0;
  TwoViewModel model = TwoViewModel::none;
};

// A frame before the map's start, placed in the new map once it exists.
struct EarlierFramePose {
  Timestamp timestamp = 0.0;
  Pose T_camera_world = Pose::Identity();
  bool is_first_keyframe = false;  // the frame the first keyframe was made from
};

// How the map starts: the one step of tracking that differs between the sensors (past it every
// keypoint is (u, v, depth, right u) for all of them, depth < 0 without one). The sensor's
// initialiser comes from its FrameBuilder (system/frame_builder.h).
class MapInitializer {
 public:
  virtual ~MapInitializer() = default;

  // Tries to start the map with `frame`. On success the frame has its pose and its map points,
  // and the new keyframes are in `map`, returned oldest first (the last is `frame`'s, the
  // tracker's reference keyframe; each goes to local mapping). Empty: not yet.
  virtual std::vector<std::shared_ptr<KeyFrame>> initialize(Frame& frame, Map& map,
                                                            InitializationProgress& progress) = 0;

  // A lost frame before a new map may start (TrackerOptions::new_map_after_seconds), kept so
  // that the map, once started, can place it: monocular as a frame between its two views,
  // depth on its first keyframe. Does nothing by default.
  virtual void observe(const Frame& /*frame*/) {}

  // After a successful initialize(): the frames before `frame` that the new map can place, oldest
  // first (monocular: the two-view pair's first frame and the frames between the pair, localised
  // on the first map's points). Each call hands them over once; empty for a one-frame start.
  virtual std::vector<EarlierFramePose> take_earlier_frames() { return {}; }

  // Tracking lost while the map has at most this many keyframes starts a new map (0: never).
  virtual std::size_t restart_when_lost_below() const { return 0; }
  // Forgets any state kept between frames (a restart).
  virtual void reset() {}
};

// One frame with at least `min_points` keypoints with depth starts the map (RGB-D, stereo). A new
// map of the atlas also places the lost frames it was shown (observe) on its first keyframe.
std::unique_ptr<MapInitializer> make_depth_map_initializer(
    int min_points, PoseOptimizerOptions pose_optimizer = {});

struct MonocularInitializerOptions {
  int min_keypoints = 100;           // a frame with fewer cannot start the map
  int min_matches = 100;             // fewer with the reference frame: take a new reference
  double search_radius_px = 100.0;   // around the keypoint's last matched position
  int max_descriptor_distance = 50;  // ORB-SLAM2's TH_LOW
  double nn_ratio = 0.9;
  int min_map_points = 100;  // after the two-keyframe bundle adjustment
  int bundle_adjustment_iterations = 20;
  // ORB-SLAM resets a monocular map lost with this few keyframes.
  std::size_t restart_when_lost_below = 5;
  TwoViewOptions two_view;
  // The frames between the pair get a pose in the first map (take_earlier_frames): at most this
  // many are kept while waiting for parallax (3 s at 30 fps; older ones stay without a pose), and
  // one is placed when its pose-only optimisation keeps this many inlier points (tracking's
  // minimum).
  std::size_t max_earlier_frames = 90;
  int min_earlier_frame_inliers = 30;
  PoseOptimizerOptions pose_optimizer;
};

// Two frames with parallax start the map (ORB-SLAM's monocular initialisation): the first frame
// with enough keypoints becomes the reference, later frames are matched to it until the
// two-view solver (solve/two_view_initializer.h) accepts a pair; the pair's points are
// triangulated, both keyframes and the points are bundle adjusted, and the map is scaled to a
// median depth of 1 in the first keyframe. The frames in between, matched with the first frame
// while parallax grew, are then localised on the points their matches reached (ORB-SLAM leaves
// them without a pose: on the synthetic demo sequence 16 of 300 frames).
std::unique_ptr<MapInitializer> make_monocular_map_initializer(
    MonocularInitializerOptions options = {});

}  // namespace pspslam
