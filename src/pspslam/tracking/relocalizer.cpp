#include "pspslam/tracking/relocalizer.h"

#include <algorithm>
#include <unordered_set>

#include "pspslam/map/frame.h"
#include "pspslam/map/keyframe.h"
#include "pspslam/map/map.h"
#include "pspslam/map/map_point.h"
#include "pspslam/place/place_recognition.h"
#include "pspslam/solve/pnp_ransac.h"
#include "pspslam/tracking/frame_pose_optimization.h"

namespace pspslam {
namespace {

void clear_matches(Frame& frame) {
  std::fill(frame.map_points.begin(), frame.map_points.end(), nullptr);
  std::fill(frame.outlier.begin(), frame.outlier.end(), 0);
}

int count_matches(const Frame& frame) {
  return static_cast<int>(std::count_if(frame.map_points.begin(), frame.map_points.end(),
                                        [](const auto& p) { return p != nullptr; }));
}

}  // namespace

Relocalizer::Relocalizer(Map& map, std::shared_ptr<PlaceRecognition> place,
                         RelocalizerOptions options)
    : map_(map), place_(std::move(place)), options_(std::move(options)) {}

RelocalizationResult Relocalizer::relocalize(Frame& frame) {
  RelocalizationResult result;
  clear_matches(frame);
  frame.clear_pose();
  if (frame.size() < options_.min_inliers) return result;  // a black / featureless frame
  frame.compute_bow(place_->vocabulary(), place_->direct_index_level());

  const CovisibilityFn covisible = [this](KeyFrameId id) {
    std::vector<KeyFrameId> ids;
    if (const auto keyframe = map_.keyframe(id)) {
      for (const auto& neighbour : keyframe->best_covisibles(10)) ids.push_back(neighbour->id());
    }
    return ids;
  };
  // Relocalisation: nothing excluded, no minimum score (ORB-SLAM2 DetectRelocalizationCandidates).
  PlaceQueryOptions query;
  query.min_score = 0.0;
  const std::vector<PlaceCandidate> candidates =
      place_->database().query(frame.bow_vector(), covisible, query);
  result.candidates = static_cast<int>(candidates.size());

  for (const PlaceCandidate& candidate : candidates) {
    // The database may briefly hold a keyframe local mapping has just culled.
    const auto keyframe = map_.keyframe(candidate.id);
    if (!keyframe || keyframe->is_bad() || !keyframe->has_bow()) continue;
    int inliers = 0;
    if (try_candidate(frame, keyframe, inliers)) {
      ++result.tried;
      if (inliers >= options_.min_inliers) {
        result.success = true;
        result.keyframe = keyframe;
        result.inliers = inliers;
        return result;
      }
    }
  }
  clear_matches(frame);
  frame.clear_pose();
  return result;
}

bool Relocalizer::try_candidate(Frame& frame, const std::shared_ptr<KeyFrame>& keyframe,
                                int& inliers) {
  clear_matches(frame);
  const std::vector<std::shared_ptr<MapPoint>> points = keyframe->map_points();
  keyframe_usable_.assign(points.size(), 0);
  for (size_t k = 0; k < points.size(); ++k)
    keyframe_usable_[k] = points[k] && !points[k]->is_bad();
  match_by_bow(keyframe->feature_vector(), keyframe->descriptors(), keyframe_usable_,
               frame.feature_vector(), frame.descriptors(), {}, options_.bow, bow_matches_);
  if (static_cast<int>(bow_matches_.size()) < options_.min_bow_matches) return false;

  // Rotation consistency, as every ORB-SLAM2 matcher.
  RotationHistogram histogram;
  for (size_t m = 0; m < bow_matches_.size(); ++m) {
    histogram.add(keyframe->keypoints()[bow_matches_[m].query].angle,
                  frame.keypoints()[bow_matches_[m].train].angle, static_cast<int>(m));
  }
  rejected_.assign(bow_matches_.size(), 0);
  for (const int m : histogram.rejected()) rejected_[m] = 1;
  points_world_.clear();
  pixels_.clear();
  keypoint_.clear();
  for (size_t m = 0; m < bow_matches_.size(); ++m) {
    if (rejected_[m]) continue;
    const int i = bow_matches_[m].train;
    frame.map_points[i] = points[bow_matches_[m].query];
    points_world_.push_back(frame.map_points[i]->position());
    pixels_.emplace_back(frame.keypoints()[i].pt.x, frame.keypoints()[i].pt.y);
    keypoint_.push_back(i);
  }
  if (static_cast<int>(keypoint_.size()) < options_.min_bow_matches) return false;

  PnpRansacOptions pnp_options;
  pnp_options.iterations = 300;
  pnp_options.min_inliers = options_.min_pnp_inliers;
  const PnpRansacResult pnp =
      solve_pnp_ransac(frame.camera().pinhole, points_world_, pixels_, pnp_options);
  if (!pnp.success) return false;
  for (size_t k = 0; k < keypoint_.size(); ++k) {
    if (!pnp.inlier[k]) frame.map_points[keypoint_[k]] = nullptr;
  }
  frame.set_pose(pnp.T_camera_world);
  inliers = optimize_and_prune(frame);
  if (inliers < options_.min_pnp_inliers) return false;

  // ORB-SLAM2: too few inliers so far; a wide projection search, then a narrow one with the
  // better pose, each followed by pose optimisation.
  if (inliers < options_.min_inliers) {
    const int added =
        search_more(frame, *keyframe, options_.wide_radius, options_.wide_max_distance);
    if (inliers + added >= options_.min_inliers) {
      inliers = optimize_and_prune(frame);
      if (inliers > options_.retry_inliers && inliers < options_.min_inliers) {
        search_more(frame, *keyframe, options_.narrow_radius, options_.narrow_max_distance);
        inliers = optimize_and_prune(frame);
      }
    }
  }
  return true;
}

int Relocalizer::optimize_and_prune(Frame& frame) {
  const PoseOptimizationResult optimized =
      optimize_frame_pose(frame, options_.pose_optimizer, pose_buffers_);
  for (size_t k = 0; k < pose_buffers_.keypoint_of_observation.size(); ++k) {
    if (!optimized.inlier[k]) frame.map_points[pose_buffers_.keypoint_of_observation[k]] = nullptr;
  }
  std::fill(frame.outlier.begin(), frame.outlier.end(), 0);
  return count_matches(frame);
}

int Relocalizer::search_more(Frame& frame, const KeyFrame& keyframe, double radius,
                             int max_distance) {
  std::unordered_set<std::uint64_t> matched;
  for (const auto& point : frame.map_points) {
    if (point) matched.insert(point->id());
  }
  projected_.clear();
  const auto project_points_of = [&](const KeyFrame& source) {
    for (const auto& point : source.map_points()) {
      if (!point || point->is_bad() || !matched.insert(point->id()).second) continue;
      ProjectedPoint p;
      if (project_map_point(point, frame, p)) projected_.push_back(std::move(p));
    }
  };
  project_points_of(keyframe);
  for (const auto& neighbour : keyframe.best_covisibles(options_.projection_neighbours)) {
    if (!neighbour->is_bad()) project_points_of(*neighbour);
  }
  MatcherOptions matcher;
  matcher.max_distance_loose = max_distance;
  return search_by_projection(frame, projected_, radius, matcher);
}

}  // namespace pspslam
