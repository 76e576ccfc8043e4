#pragma once

// Loop detection and verification (ORB-SLAM2 LoopClosing::DetectLoop and ComputeSim3): the loop
// transform is a Sim(3) whose scale is estimated for monocular maps (scale drift) and fixed to 1
// where depth fixes it (RGB-D, stereo). Synchronous; LoopClosing runs it on its thread, tests
// call it directly.
//
//   LoopDetector detector(map, place, options);
//   for each keyframe local mapping has finished:
//     auto candidates = detector.detect(keyframe);        // BoW + covisibility consistency
//     if (auto loop = detector.verify(keyframe, candidates)) correct_loop(..., *loop);

#include <cstdint>
#include <memory>
#include <optional>
#include <set>
#include <vector>

#include "pspslam/core/types.h"
#include "pspslam/loop/loop_matching.h"
#include "pspslam/solve/rigid_alignment.h"

namespace pspslam {

class KeyFrame;
class Map;
class MapPoint;
class PlaceRecognition;

struct LoopDetectorOptions {
  // No loop is searched until the map has this many keyframes, nor within this many keyframes
  // of the last closed loop (ORB-SLAM2: 10).
  std::uint64_t min_keyframes_between_loops = 10;
  // A candidate's covisibility group must be found again by this many consecutive keyframes.
  int consistency_threshold = 3;
  LoopMatchingOptions matching;
  int min_descriptor_matches = 20;  // candidates with fewer are not tried
  RigidRansacOptions ransac;        // min_inliers 20, 300 iterations; estimate_scale: Sim(3)
  // RANSAC inlier test in 3D, per pair: |Δ| <= base + per_depth · z + per_depth2 · z² (z: the
  // larger depth, in the map's units). RGB-D depth noise grows with z² (metres); a monocular
  // map has no unit, so its test is relative to the depth (the sensor's FrameBuilder sets it).
  double ransac_error_base = 0.02;
  double ransac_error_per_depth = 0.0;
  double ransac_error_per_depth2 = 0.01;
  double guided_radius = 7.5;       // pixels at level 0 (SearchBySim3)
  double reprojection_chi2 = 9.21;  // 2-dof χ² at 99%, in both images
  int min_verified_inliers = 20;    // after refinement (ORB-SLAM2: 20)
  // Then refine the transform by reprojection in both keyframes (optimize_similarity, ORB-SLAM2
  // OptimizeSim3). Monocular: the 3D fit above weighs the poorly known depth of triangulated
  // points like their bearing. RGB-D and stereo keep the 3D fit (measured depth).
  bool refine_by_reprojection = false;
  double projection_radius = 10.0;  // candidate neighbourhood projected into the keyframe
  int min_projection_matches = 40;  // total matches to accept (ORB-SLAM2: 40)
};

// An accepted loop: where the current keyframe should be, and what it matched.
struct DetectedLoop {
  std::shared_ptr<KeyFrame> current;
  std::shared_ptr<KeyFrame> matched;  // the loop keyframe (old side)
  Sim3 S_current_matched;             // scale 1 unless the detector estimates it (monocular)
  // Corrected pose of the current keyframe: S_current_matched · T_matched_world, in the units of
  // the current keyframe's map (its rescaled_pose() is the pose in the loop side's units).
  Sim3 S_current_world;
  // Per keypoint of `current`: the loop map point matched to it (nullptr: none).
  std::vector<std::shared_ptr<MapPoint>> matched_points;
  // Map points of the matched keyframe and its covisible keyframes (fused into the current
  // neighbourhood by the correction).
  std::vector<std::shared_ptr<MapPoint>> loop_points;
  int verified_inliers = 0;
  int total_matches = 0;
};

struct LoopDetectorStats {
  std::uint64_t keyframes_checked = 0;
  std::uint64_t bow_candidates = 0;         // summed over keyframes
  std::uint64_t consistent_candidates = 0;  // passed the consistency test
  std::uint64_t rejected_geometry = 0;      // consistent but failed verification
  std::uint64_t loops_detected = 0;
};

class LoopDetector {
 public:
  // `map` and `place` must outlive the detector.
  LoopDetector(const Map& map, const PlaceRecognition& place, LoopDetectorOptions options = {});

  // Loop candidates whose covisibility group has been consistent over the last
  // consistency_threshold keyframes (may be empty). Updates the consistency state.
  std::vector<std::shared_ptr<KeyFrame>> detect(const std::shared_ptr<KeyFrame>& keyframe);

  // Tries the candidates in order; the first that passes the geometric checks is returned.
  std::optional<DetectedLoop> verify(const std::shared_ptr<KeyFrame>& keyframe,
                                     const std::vector<std::shared_ptr<KeyFrame>>& candidates);

  // Loops are not searched again within min_keyframes_between_loops of this keyframe.
  void loop_closed_at(std::uint64_t keyframe_id);

  const LoopDetectorStats& stats() const { return stats_; }

 private:
  struct ConsistentGroup {
    std::set<std::uint64_t> keyframes;
    int consistency = 0;
  };
  std::optional<DetectedLoop> verify_candidate(const std::shared_ptr<KeyFrame>& keyframe,
                                               const std::shared_ptr<KeyFrame>& candidate);

  const Map& map_;
  const PlaceRecognition& place_;
  LoopDetectorOptions options_;
  std::vector<ConsistentGroup> consistent_groups_;
  std::optional<std::uint64_t> last_loop_keyframe_;
  LoopDetectorStats stats_;
};

}  // namespace pspslam
