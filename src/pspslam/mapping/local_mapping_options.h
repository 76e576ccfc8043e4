#pragma once

#include "pspslam/config/config.h"
#include "pspslam/optimize/local_bundle_adjustment.h"

namespace pspslam {

// Local mapping parameters; defaults are ORB-SLAM2's values for RGB-D input.
struct LocalMappingOptions {
  // New points by triangulation against the best covisible keyframes.
  int triangulation_neighbours = 10;
  // Keypoints with depth closer than this (metres; the camera's depth_threshold) are "close":
  // they become map points directly from their depth, and only they count in keyframe culling.
  double close_depth = 4.0;
  // Fewer close points than this and the nearest far ones are promoted too (ORB-SLAM2: 100).
  int min_depth_points = 100;
  // Hamming distance of an accepted match (ORB-SLAM2's TH_LOW).
  int max_descriptor_distance = 50;
  // Duplicate fusion: first neighbours, and second neighbours per first neighbour.
  int fusion_neighbours = 10;
  int fusion_second_neighbours = 5;
  double fusion_radius = 3.0;  // pixels at level 0, times the level scale
  // Recent map point culling.
  double min_found_ratio = 0.25;
  int min_observations = 3;       // a depth observation counts twice
  int culling_keyframe_span = 2;  // keyframes after creation before min_observations applies
  int probation_keyframes = 3;    // after this many keyframes a point is no longer "recent"
  // Redundant keyframe culling: a keyframe goes when more than this fraction of its close map
  // points are seen by at least redundant_observers other keyframes at the same or finer scale.
  double redundant_ratio = 0.9;
  int redundant_observers = 3;
  // Only points with a close depth count towards redundancy (false: every point, monocular).
  bool redundancy_needs_depth = true;
  bool cull_keyframes = true;
  BaOptions bundle_adjustment;
  // Local BA window: the new keyframe and at most this many of its best covisible keyframes
  // (0: all of them, as ORB-SLAM2). The rest that see the window's points are held fixed.
  int max_local_keyframes = 0;
  // Of the keyframes held fixed around it, the ones that see the most of its points (0: all).
  int max_fixed_keyframes = 0;
  // Weight of tracking's relative poses between keyframes in local BA (0: none; see
  // LocalWindowOptions::tracked_motion_weight).
  double tracked_motion_weight = 0.0;
  // Nice increment of the local mapping thread (core/thread_priority.h; real-time runs).
  int thread_nice = 0;

  // Defaults, with the sensor's close-depth threshold from the config.
  static LocalMappingOptions from_config(const SystemConfig& config) {
    LocalMappingOptions options;
    options.close_depth = config.camera.depth_threshold;
    return options;
  }
};

}  // namespace pspslam
