#include "pspslam/mapping/local_mapper.h"

#include <chrono>
#include <unordered_set>

#include "pspslam/map/keyframe.h"
#include "pspslam/map/map.h"
#include "pspslam/map/map_point.h"
#include "pspslam/mapping/keyframe_culling.h"
#include "pspslam/mapping/keyframe_matching.h"
#include "pspslam/mapping/local_bundle_adjuster.h"
#include "pspslam/mapping/map_point_creation.h"
#include "pspslam/place/place_recognition.h"

namespace pspslam {

LocalMapper::LocalMapper(std::shared_ptr<Map> map, LocalMappingOptions options,
                         std::shared_ptr<PlaceRecognition> place)
    : map_(std::move(map)), options_(std::move(options)), place_(std::move(place)) {}

void LocalMapper::process(const std::shared_ptr<KeyFrame>& keyframe,
                          const std::function<bool()>& has_new_keyframe) {
  const auto start = std::chrono::steady_clock::now();
  const auto keyframe_waiting = [&] { return has_new_keyframe && has_new_keyframe(); };

  insert_keyframe_into_map(keyframe);
  if (place_ && !keyframe->is_bad()) {
    // Here rather than in tracking (ORB-SLAM2 ProcessNewKeyFrame): the vocabulary tree descent
    // per keyframe stays off the tracking thread.
    keyframe->compute_bow(place_->vocabulary(), place_->direct_index_level());
    place_->database().add(keyframe->id(), keyframe->bow_vector());
  }
  cull_recent_points(*keyframe);
  const auto triangulated =
      create_points_by_triangulation(*map_, keyframe, options_, has_new_keyframe);
  add_recent(triangulated);
  stats_.points_triangulated += triangulated.size();

  if (!keyframe_waiting()) fuse_with_neighbours(keyframe);

  if (!keyframe_waiting() && map_->num_keyframes() > 2) {
    BaOptions ba_options = options_.bundle_adjustment;
    const std::function<bool()> caller_stop = ba_options.should_stop;
    ba_options.should_stop = [&] { return keyframe_waiting() || (caller_stop && caller_stop()); };
    const LocalBundleAdjustmentReport report = run_local_bundle_adjustment(
        *map_, keyframe, ba_options,
        {.max_covisibles = static_cast<size_t>(options_.max_local_keyframes),
         .max_fixed_keyframes = static_cast<size_t>(options_.max_fixed_keyframes),
         .tracked_motion_weight = options_.tracked_motion_weight});
    ++stats_.bundle_adjustments;
    stats_.bundle_adjustments_interrupted += report.result.stopped_early;
    stats_.ba_outliers_removed += report.outliers_removed;
    stats_.last_bundle_adjustment_seconds = report.seconds;
    stats_.last_bundle_adjustment_cpu_ms = report.cpu_ms;
  }
  if (!keyframe_waiting() && options_.cull_keyframes) {
    const auto forget = [this](std::uint64_t id) {
      if (place_) place_->database().erase(id);
    };
    stats_.keyframes_culled += cull_redundant_keyframes(*map_, keyframe, options_, forget);
  }

  // Points made bad as a side effect (an observation erased, a duplicate replaced) would
  // otherwise stay owned by the Map forever.
  stats_.bad_points_swept += map_->erase_bad_map_points();
  ++stats_.keyframes_processed;
  stats_.last_keyframe_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void LocalMapper::insert_keyframe_into_map(const std::shared_ptr<KeyFrame>& keyframe) {
  const std::vector<std::shared_ptr<MapPoint>> points = keyframe->map_points();
  std::vector<std::shared_ptr<MapPoint>> created_for_keyframe;
  for (int i = 0; i < static_cast<int>(points.size()); ++i) {
    const auto& point = points[i];
    if (!point) continue;
    const int observed_index = point->keypoint_index_in(keyframe->id());
    if (observed_index >= 0 && observed_index != i) {
      // Tracking matched the point to two keypoints; a point has one observation per keyframe,
      // so the second association would be invisible to BA and culling. Keep the first.
      keyframe->erase_map_point(i);
      continue;
    }
    if (point->first_keyframe_id == keyframe->id()) {
      // Created by tracking together with this keyframe: it starts its probation here.
      if (observed_index < 0) point->add_observation(keyframe, i);
      created_for_keyframe.push_back(point);
    } else if (observed_index < 0) {
      point->add_observation(keyframe, i);
      point->update_normal_and_depth(keyframe->pyramid());
      point->compute_distinctive_descriptor();
    }
  }
  add_recent(created_for_keyframe);
  keyframe->update_connections();
  map_->add_keyframe(keyframe);

  const auto from_depth = create_points_from_depth(*map_, keyframe, options_);
  add_recent(from_depth);
  // Seen by this keyframe alone, the new points add no covisibility edges yet.
  stats_.points_from_depth += from_depth.size();
}

void LocalMapper::cull_recent_points(const KeyFrame& keyframe) {
  const std::uint64_t current = keyframe.id();
  size_t kept = 0;
  for (auto& weak : recent_points_) {
    const auto point = weak.lock();
    if (!point || point->is_bad()) continue;
    const std::uint64_t first = point->first_keyframe_id;
    const std::uint64_t age = current > first ? current - first : 0;
    bool cull = false;
    if (point->found_ratio() < options_.min_found_ratio) {
      cull = true;  // tracking predicted it in view but rarely matched it
    } else if (age >= static_cast<std::uint64_t>(options_.culling_keyframe_span) &&
               point->num_observations() <= options_.min_observations) {
      cull = true;  // the following keyframes did not pick it up
    } else if (age >= static_cast<std::uint64_t>(options_.probation_keyframes)) {
      continue;  // survived its probation
    }
    if (cull) {
      map_->erase_map_point(point);
      ++stats_.points_culled;
      continue;
    }
    recent_points_[kept++] = weak;
  }
  recent_points_.resize(kept);
}

void LocalMapper::fuse_with_neighbours(const std::shared_ptr<KeyFrame>& keyframe) {
  std::vector<std::shared_ptr<KeyFrame>> targets;
  std::unordered_set<std::uint64_t> seen{keyframe->id()};
  for (const auto& neighbour : keyframe->best_covisibles(options_.fusion_neighbours)) {
    if (!seen.insert(neighbour->id()).second) continue;
    targets.push_back(neighbour);
    for (const auto& second : neighbour->best_covisibles(options_.fusion_second_neighbours)) {
      if (seen.insert(second->id()).second) targets.push_back(second);
    }
  }

  // The keyframe's points into each neighbour...
  const std::vector<std::shared_ptr<MapPoint>> own_points = keyframe->map_points();
  for (const auto& target : targets) {
    stats_.points_fused += fuse_into_keyframe(*map_, target, own_points, options_.fusion_radius,
                                              options_.max_descriptor_distance);
  }
  // ...and the neighbours' points into the keyframe.
  std::vector<std::shared_ptr<MapPoint>> candidates;
  std::unordered_set<std::uint64_t> candidate_ids;
  for (const auto& target : targets) {
    for (const auto& point : target->map_points()) {
      if (point && candidate_ids.insert(point->id()).second) candidates.push_back(point);
    }
  }
  stats_.points_fused += fuse_into_keyframe(*map_, keyframe, candidates, options_.fusion_radius,
                                            options_.max_descriptor_distance);

  for (const auto& point : keyframe->map_points()) {
    if (!point) continue;
    point->compute_distinctive_descriptor();
    point->update_normal_and_depth(keyframe->pyramid());
  }
  keyframe->update_connections();
}

void LocalMapper::add_recent(const std::vector<std::shared_ptr<MapPoint>>& points) {
  for (const auto& point : points) recent_points_.push_back(point);
}

}  // namespace pspslam
