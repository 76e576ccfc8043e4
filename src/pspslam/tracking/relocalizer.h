#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <vector>

#include "pspslam/match/orb_matcher.h"
#include "pspslam/optimize/pose_optimizer.h"
#include "pspslam/place/bow_matching.h"
#include "pspslam/tracking/frame_pose_optimization.h"

namespace pspslam {

class Frame;
class KeyFrame;
class Map;
class PlaceRecognition;

// ORB-SLAM2's relocalisation thresholds.
struct RelocalizerOptions {
  BowMatchOptions bow;          // TH_LOW 50, ratio 0.75
  int min_bow_matches = 15;     // candidates with fewer BoW matches are not tried
  int min_pnp_inliers = 10;     // PnP RANSAC / first pose optimisation
  int min_inliers = 50;         // accepted pose
  int retry_inliers = 30;       // above this (and below min_inliers): a second, narrow search
  double wide_radius = 2.5;     // search_by_projection scale ~10 px at level 0 (ORB-SLAM2 th=10)
  double narrow_radius = 0.75;  // ~3 px (ORB-SLAM2 th=3)
  int wide_max_distance = 100;
  int narrow_max_distance = 64;
  size_t projection_neighbours = 10;  // candidate's best covisibles whose points are projected
  PoseOptimizerOptions pose_optimizer;
};

struct RelocalizationResult {
  bool success = false;
  std::shared_ptr<KeyFrame> keyframe;  // the candidate the pose came from
  int candidates = 0;                  // returned by the keyframe database
  int tried = 0;                       // candidates that gave a PnP pose
  int inliers = 0;
};

// Relocalisation of a lost frame (ORB-SLAM2 Tracking::Relocalization): the frame's BoW vector
// queries the keyframe database; each candidate keyframe is matched by vocabulary node
// (match_by_bow + rotation check), EPnP RANSAC gives a pose without any prior, pose-only
// optimisation refines it, and search by projection of the candidate's (and its covisibles')
// map points adds matches until at least min_inliers agree.
//
// Runs on the tracking thread with Map::update_mutex() held (as the tracker does); costs nothing
// while tracking is fine because it is only called for lost frames.
class Relocalizer {
 public:
  // `map` must outlive the relocaliser.
  Relocalizer(Map& map, std::shared_ptr<PlaceRecognition> place, RelocalizerOptions options = {});

  // On success the frame has its pose and inlier map point matches (outlier flags cleared);
  // on failure it has no pose and no matches.
  RelocalizationResult relocalize(Frame& frame);

  const RelocalizerOptions& options() const { return options_; }

 private:
  bool try_candidate(Frame& frame, const std::shared_ptr<KeyFrame>& keyframe, int& inliers);
  // Pose-only optimisation on the frame's matches; drops outliers, returns the inliers left.
  int optimize_and_prune(Frame& frame);
  // Projects the candidate's and its neighbours' points not matched yet; returns new matches.
  int search_more(Frame& frame, const KeyFrame& keyframe, double radius, int max_distance);

  Map& map_;
  std::shared_ptr<PlaceRecognition> place_;
  RelocalizerOptions options_;

  // Reused buffers (relocalisation runs on consecutive lost frames).
  std::vector<std::uint8_t> keyframe_usable_;
  std::vector<BowMatch> bow_matches_;
  std::vector<std::uint8_t> rejected_;         // by the rotation histogram, per BoW match
  std::vector<Eigen::Vector3d> points_world_;  // PnP correspondences
  std::vector<Eigen::Vector2d> pixels_;
  std::vector<int> keypoint_;
  FramePoseBuffers pose_buffers_;
  std::vector<ProjectedPoint> projected_;
};

}  // namespace pspslam
