#include "pspslam/loop/loop_detector.h"

#include <algorithm>
#include <unordered_set>

#include "pspslam/map/keyframe.h"
#include "pspslam/map/map.h"
#include "pspslam/map/map_point.h"
#include "pspslam/optimize/similarity_optimization.h"
#include "pspslam/place/place_recognition.h"

namespace pspslam {
namespace {

// ORB-SLAM2 groups a candidate with its covisible keyframes for the consistency test.
std::set<std::uint64_t> covisibility_group(const KeyFrame& keyframe) {
  std::set<std::uint64_t> group{keyframe.id()};
  for (const auto& neighbour : keyframe.covisibles()) group.insert(neighbour->id());
  return group;
}

bool reprojects(const KeyFrame& keyframe, int index, const Eigen::Vector3d& point_camera,
                double chi2) {
  if (point_camera.z() <= 0.0) return false;
  const Eigen::Vector2d pixel = keyframe.camera().pinhole.project(point_camera);
  const cv::KeyPoint& keypoint = keyframe.keypoints()[index];
  const double du = keypoint.pt.x - pixel.x();
  const double dv = keypoint.pt.y - pixel.y();
  return (du * du + dv * dv) * keyframe.pyramid().inv_sigma2[keypoint.octave] <= chi2;
}

// One verified pair: keypoint `index` of the current keyframe and the candidate's keypoint of
// the matched point, both map points expressed in their own camera.
struct PointPair {
  int index = -1;
  int candidate_index = -1;
  Eigen::Vector3d in_current = Eigen::Vector3d::Zero();
  Eigen::Vector3d in_candidate = Eigen::Vector3d::Zero();
};

std::vector<PointPair> point_pairs(const KeyFrame& current, const KeyFrame& candidate,
                                   const std::vector<std::shared_ptr<MapPoint>>& matched) {
  std::vector<PointPair> pairs;
  const auto own = current.map_points();
  const Pose T_current_world = current.T_camera_world();
  const Pose T_candidate_world = candidate.T_camera_world();
  for (int i = 0; i < current.size(); ++i) {
    if (!matched[i] || !own[i]) continue;
    const int j = matched[i]->keypoint_index_in(candidate.id());
    if (j < 0) continue;
    pairs.push_back(
        {i, j, T_current_world * own[i]->position(), T_candidate_world * matched[i]->position()});
  }
  return pairs;
}

// 1. RANSAC on 3D-3D pairs (each map point in its own keyframe's camera). Matches outside its
// consensus are dropped.
std::optional<Sim3> ransac_alignment(const KeyFrame& current, const KeyFrame& candidate,
                                     std::vector<std::shared_ptr<MapPoint>>& matched,
                                     const LoopDetectorOptions& options) {
  const std::vector<PointPair> pairs = point_pairs(current, candidate, matched);
  std::vector<RigidCorrespondence> correspondences;
  correspondences.reserve(pairs.size());
  for (const PointPair& pair : pairs) {
    const double z = std::max(pair.in_current.z(), pair.in_candidate.z());
    correspondences.push_back({pair.in_candidate, pair.in_current,
                               options.ransac_error_base + options.ransac_error_per_depth * z +
                                   options.ransac_error_per_depth2 * z * z});
  }
  RigidRansacOptions ransac = options.ransac;
  ransac.seed = current.id() * 7919 + candidate.id();
  const RigidRansacResult estimate = solve_rigid_ransac(correspondences, ransac);
  if (!estimate.success) return std::nullopt;
  for (size_t k = 0; k < pairs.size(); ++k) {
    if (!estimate.inlier[k]) matched[pairs[k].index] = nullptr;
  }
  return estimate.S_target_source;
}

// Three rounds of alignment on the pairs that reproject in both images (the role of
// ORB-SLAM2's OptimizeSim3), with weights 1/z² (depth noise). Returns the inlier count, none
// when too few pairs hold or an alignment fails.
std::optional<int> align_reprojecting_pairs(const KeyFrame& current, const KeyFrame& candidate,
                                            const std::vector<PointPair>& pairs,
                                            const LoopDetectorOptions& options,
                                            Sim3& S_current_candidate,
                                            std::vector<std::uint8_t>& inlier) {
  int inliers = 0;
  for (int round = 0; round < 3; ++round) {
    const Sim3 S_candidate_current = S_current_candidate.inverse();
    inliers = 0;
    std::vector<Eigen::Vector3d> source;
    std::vector<Eigen::Vector3d> target;
    std::vector<double> weights;
    for (size_t k = 0; k < pairs.size(); ++k) {
      const PointPair& pair = pairs[k];
      inlier[k] = reprojects(current, pair.index, S_current_candidate * pair.in_candidate,
                             options.reprojection_chi2) &&
                  reprojects(candidate, pair.candidate_index, S_candidate_current * pair.in_current,
                             options.reprojection_chi2);
      if (!inlier[k]) continue;
      ++inliers;
      source.push_back(pair.in_candidate);
      target.push_back(pair.in_current);
      const double z = std::max(pair.in_current.z(), pair.in_candidate.z());
      weights.push_back(1.0 / std::max(z * z, 0.01));
    }
    if (inliers < options.min_verified_inliers) return std::nullopt;
    if (options.ransac.estimate_scale) {
      const std::optional<Sim3> refined = align_similarity(source, target, weights);
      if (!refined) return std::nullopt;
      S_current_candidate = *refined;
    } else {
      const std::optional<Pose> refined = align_rigid(source, target, weights);
      if (!refined) return std::nullopt;
      S_current_candidate = Sim3(*refined);
    }
  }
  return inliers;
}

// Refinement of the similarity on the reprojection errors of the inlier pairs in both images.
// Returns the inlier count, none when too few remain.
std::optional<int> refine_by_reprojection(const KeyFrame& current, const KeyFrame& candidate,
                                          const std::vector<PointPair>& pairs,
                                          const LoopDetectorOptions& options,
                                          Sim3& S_current_candidate,
                                          std::vector<std::uint8_t>& inlier) {
  std::vector<SimilarityPair> reprojected;
  std::vector<size_t> pair_of;
  for (size_t k = 0; k < pairs.size(); ++k) {
    if (!inlier[k]) continue;
    const cv::KeyPoint& in_current = current.keypoints()[pairs[k].index];
    const cv::KeyPoint& in_candidate = candidate.keypoints()[pairs[k].candidate_index];
    reprojected.push_back({pairs[k].in_current, pairs[k].in_candidate,
                           Eigen::Vector2d(in_current.pt.x, in_current.pt.y),
                           Eigen::Vector2d(in_candidate.pt.x, in_candidate.pt.y),
                           current.pyramid().inv_sigma2[in_current.octave],
                           candidate.pyramid().inv_sigma2[in_candidate.octave]});
    pair_of.push_back(k);
  }
  SimilarityOptimizationOptions refinement;
  refinement.estimate_scale = options.ransac.estimate_scale;
  const SimilarityOptimizationResult refined =
      optimize_similarity(current.camera().pinhole, S_current_candidate, reprojected, refinement);
  if (refined.num_inliers < options.min_verified_inliers) return std::nullopt;
  S_current_candidate = refined.S_a_b;
  for (size_t j = 0; j < pair_of.size(); ++j) inlier[pair_of[j]] = refined.inlier[j];
  return refined.num_inliers;
}

// Keeps the matches of inlier pairs only.
void keep_inlier_matches(const KeyFrame& current, const std::vector<PointPair>& pairs,
                         const std::vector<std::uint8_t>& inlier,
                         std::vector<std::shared_ptr<MapPoint>>& matched) {
  for (size_t k = 0; k < pairs.size(); ++k) {
    if (!inlier[k]) matched[pairs[k].index] = nullptr;
  }
  // Matches without a point in the current keyframe are not pairs; they were never checked.
  const auto own = current.map_points();
  for (int i = 0; i < current.size(); ++i) {
    if (matched[i] && !own[i]) matched[i] = nullptr;
  }
}

// The points of the candidate and its covisible keyframes, each once.
std::vector<std::shared_ptr<MapPoint>> neighbourhood_points(
    const std::shared_ptr<KeyFrame>& candidate) {
  std::vector<std::shared_ptr<MapPoint>> points;
  std::unordered_set<const MapPoint*> seen;
  auto neighbourhood = candidate->covisibles();
  neighbourhood.push_back(candidate);
  for (const auto& member : neighbourhood) {
    for (const auto& point : member->map_points()) {
      if (point && seen.insert(point.get()).second) points.push_back(point);
    }
  }
  return points;
}

}  // namespace

LoopDetector::LoopDetector(const Map& map, const PlaceRecognition& place,
                           LoopDetectorOptions options)
    : map_(map), place_(place), options_(std::move(options)) {}

void LoopDetector::loop_closed_at(std::uint64_t keyframe_id) {
  last_loop_keyframe_ = keyframe_id;
  consistent_groups_.clear();
}

std::vector<std::shared_ptr<KeyFrame>> LoopDetector::detect(
    const std::shared_ptr<KeyFrame>& keyframe) {
  ++stats_.keyframes_checked;
  const std::uint64_t since = last_loop_keyframe_ ? *last_loop_keyframe_ : 0;
  if (keyframe->id() < since + options_.min_keyframes_between_loops || !keyframe->has_bow()) {
    return {};
  }
  // The lowest similarity to its own covisible keyframes: a loop candidate must look at least
  // as similar as the keyframes it is known to share the view with.
  const auto neighbours = keyframe->covisibles();
  double min_score = 1.0;
  PlaceQueryOptions query;
  query.excluded.push_back(keyframe->id());
  for (const auto& neighbour : neighbours) {
    query.excluded.push_back(neighbour->id());
    if (!neighbour->has_bow()) continue;
    min_score = std::min(min_score, bow_score(keyframe->bow_vector(), neighbour->bow_vector()));
  }
  if (neighbours.empty()) min_score = 0.0;
  query.min_score = min_score;
  // Candidate groups are scored over their best covisible keyframes, read from the map.
  const auto covisible = [this](KeyFrameId id) {
    std::vector<KeyFrameId> ids;
    if (const auto member = map_.keyframe(id)) {
      for (const auto& neighbour : member->best_covisibles(10)) ids.push_back(neighbour->id());
    }
    return ids;
  };
  const auto candidates = place_.database().query(keyframe->bow_vector(), covisible, query);
  stats_.bow_candidates += candidates.size();
  if (candidates.empty()) {
    consistent_groups_.clear();
    return {};
  }

  // Covisibility consistency (ORB-SLAM2): each candidate's group is compared with the groups
  // that were consistent for the previous keyframe; sharing a keyframe continues the chain.
  std::vector<ConsistentGroup> current_groups;
  std::vector<bool> previous_extended(consistent_groups_.size(), false);
  std::vector<std::shared_ptr<KeyFrame>> accepted;
  for (const PlaceCandidate& candidate : candidates) {
    const auto candidate_keyframe = map_.keyframe(candidate.id);
    if (!candidate_keyframe || candidate_keyframe->is_bad()) continue;
    const std::set<std::uint64_t> group = covisibility_group(*candidate_keyframe);
    bool enough = false;
    bool consistent_for_some = false;
    for (size_t g = 0; g < consistent_groups_.size(); ++g) {
      const auto& previous = consistent_groups_[g].keyframes;
      const bool shares = std::any_of(group.begin(), group.end(),
                                      [&](std::uint64_t id) { return previous.contains(id); });
      if (!shares) continue;
      consistent_for_some = true;
      const int consistency = consistent_groups_[g].consistency + 1;
      if (!previous_extended[g]) {
        current_groups.push_back({group, consistency});
        previous_extended[g] = true;
      }
      if (consistency >= options_.consistency_threshold && !enough) {
        accepted.push_back(candidate_keyframe);
        enough = true;
      }
    }
    if (!consistent_for_some) current_groups.push_back({group, 0});
  }
  consistent_groups_ = std::move(current_groups);
  stats_.consistent_candidates += accepted.size();
  return accepted;
}

std::optional<DetectedLoop> LoopDetector::verify(
    const std::shared_ptr<KeyFrame>& keyframe,
    const std::vector<std::shared_ptr<KeyFrame>>& candidates) {
  for (const auto& candidate : candidates) {
    if (candidate->is_bad() || keyframe->is_bad()) continue;
    if (auto loop = verify_candidate(keyframe, candidate)) {
      ++stats_.loops_detected;
      return loop;
    }
    ++stats_.rejected_geometry;
  }
  return std::nullopt;
}

std::optional<DetectedLoop> LoopDetector::verify_candidate(
    const std::shared_ptr<KeyFrame>& keyframe, const std::shared_ptr<KeyFrame>& candidate) {
  std::vector<std::shared_ptr<MapPoint>> matched(static_cast<size_t>(keyframe->size()));
  if (match_by_descriptor(*keyframe, *candidate, matched, options_.matching) <
      options_.min_descriptor_matches) {
    return std::nullopt;
  }

  // 1. RANSAC on 3D-3D pairs.
  const std::optional<Sim3> estimate = ransac_alignment(*keyframe, *candidate, matched, options_);
  if (!estimate) return std::nullopt;
  Sim3 S_current_candidate = *estimate;

  // 2. Guided search for more pairs, then refinement on the pairs that reproject in both
  // images (the role of ORB-SLAM2's OptimizeSim3), with weights 1/z² (depth noise).
  match_by_transform(*keyframe, *candidate, S_current_candidate, matched, options_.guided_radius,
                     options_.matching);
  const std::vector<PointPair> pairs = point_pairs(*keyframe, *candidate, matched);
  std::vector<std::uint8_t> inlier(pairs.size(), 0);
  std::optional<int> inliers =
      align_reprojecting_pairs(*keyframe, *candidate, pairs, options_, S_current_candidate, inlier);
  if (!inliers) return std::nullopt;
  if (options_.refine_by_reprojection) {
    inliers =
        refine_by_reprojection(*keyframe, *candidate, pairs, options_, S_current_candidate, inlier);
    if (!inliers) return std::nullopt;
  }
  keep_inlier_matches(*keyframe, pairs, inlier, matched);

  // 3. Project the candidate's neighbourhood into the corrected current keyframe.
  DetectedLoop loop;
  loop.current = keyframe;
  loop.matched = candidate;
  loop.S_current_matched = S_current_candidate;
  loop.S_current_world = S_current_candidate * candidate->T_camera_world();
  loop.verified_inliers = *inliers;
  loop.loop_points = neighbourhood_points(candidate);
  match_by_projection(*keyframe, loop.S_current_world.rescaled_pose(), loop.loop_points, matched,
                      options_.projection_radius, options_.matching);
  loop.total_matches = static_cast<int>(
      std::count_if(matched.begin(), matched.end(), [](const auto& p) { return p != nullptr; }));
  if (loop.total_matches < options_.min_projection_matches) return std::nullopt;
  loop.matched_points = std::move(matched);
  return loop;
}

}  // namespace pspslam
