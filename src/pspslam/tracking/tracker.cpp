#include "pspslam/tracking/tracker.h"

#include <mutex>

#include "pspslam/core/error.h"
#include "pspslam/map/keyframe.h"
#include "pspslam/map/map.h"
#include "pspslam/map/map_point.h"
#include "pspslam/tracking/frame_pose_optimization.h"
#include "pspslam/tracking/keyframe_builder.h"
#include "pspslam/tracking/keyframe_sink.h"
#include "pspslam/tracking/trajectory_refinement.h"

namespace pspslam {
const char* to_string(TrackingState state) {
  switch (state) {
    case TrackingState::kNotInitialized:
      return "not_initialized";
    case TrackingState::kOk:
      return "ok";
    case TrackingState::kLost:
      return "lost";
  }
  return "?";
}

const char* to_string(TrackingMethod method) {
  switch (method) {
    case TrackingMethod::kNone:
      return "none";
    case TrackingMethod::kInitialization:
      return "initialization";
    case TrackingMethod::kMotionModel:
      return "motion_model";
    case TrackingMethod::kReferenceKeyFrame:
      return "reference_keyframe";
    case TrackingMethod::kRecovery:
      return "recovery";
    case TrackingMethod::kRelocalisation:
      return "relocalisation";
  }
  return "?";
}

Tracker::Tracker(Map& map, KeyFrameSink* sink, TrackerOptions options,
                 std::shared_ptr<PlaceRecognition> place,
                 std::unique_ptr<MapInitializer> initializer)
    : map_(map),
      sink_(sink),
      options_(std::move(options)),
      mover_guard_(options_.mover_guard),
      local_map_(options_.max_local_keyframes),
      initializer_(initializer ? std::move(initializer)
                               : make_depth_map_initializer(options_.min_initial_depth_points,
                                                            options_.pose_optimizer)) {
  if (place)
    relocalizer_ = std::make_unique<Relocalizer>(map_, std::move(place), options_.relocalizer);
}

Tracker::~Tracker() = default;

TrackResult Tracker::track(Frame frame, std::optional<std::uint64_t> judged_through_frame) {
  std::lock_guard map_lock(map_.update_mutex());
  judged_through_frame_ =
      options_.judged_points_first ? judged_through_frame : std::optional<std::uint64_t>();
  unjudged_matches_set_aside_ = 0;
  TrackResult result;
  result.frame_id = frame.id();
  result.timestamp = frame.timestamp();
  result.num_keypoints = frame.size();

  if (state_ == TrackingState::kNotInitialized) {
    if (relocalize_in_atlas(frame)) {
      result.method = TrackingMethod::kRelocalisation;
      finish_tracked_frame(frame, result);
    } else {
      start_map(frame, result);
    }
  } else {
    if (last_frame_) replace_replaced_points(*last_frame_);
    motion_prior_.reset();
    predicted_pose_.reset();
    bool ok = false;
    if (state_ == TrackingState::kOk && velocity_ && last_frame_ && last_frame_->has_pose()) {
      ok = track_with_motion_model(frame);
      if (ok) result.method = TrackingMethod::kMotionModel;
      if (!ok) motion_prior_.reset();  // the prediction failed to match: do not trust it
    }
    if (!ok && state_ == TrackingState::kLost && relocalizer_) {
      ok = relocalize(frame);
      if (ok) result.method = TrackingMethod::kRelocalisation;
    }
    if (!ok) {
      const bool recovering = state_ == TrackingState::kLost;
      ok = track_reference_keyframe(frame, recovering);
      if (ok) {
        result.method = recovering ? TrackingMethod::kRecovery : TrackingMethod::kReferenceKeyFrame;
        if (recovering) last_recovery_frame_id_ = frame.id();
      }
    }
    if (ok) ok = track_local_map(frame);
    if (ok) {
      finish_tracked_frame(frame, result);
    } else {
      on_lost(frame, result);
    }
  }

  result.state = state_;
  result.map_id = map_.active_map();
  result.unjudged_matches_set_aside = unjudged_matches_set_aside_;
  if (state_ == TrackingState::kOk && frame.has_pose()) {
    lost_since_.reset();
    result.T_world_camera = frame.T_world_camera();
    if (last_tracked_pose_ && last_frame_ && last_frame_->has_pose()) {
      velocity_ = orthonormalized(frame.T_camera_world() * last_frame_->T_camera_world().inverse());
    } else {
      velocity_.reset();
    }
    last_tracked_pose_ = frame.T_camera_world();
    anchors_.push_back({frame.timestamp(), reference_keyframe_,
                        frame.T_camera_world() * reference_keyframe_->T_world_camera(),
                        frame.T_camera_world(), result.keyframe_inserted, map_epoch_,
                        result.map_id});
  } else {
    velocity_.reset();
    angular_velocity_.setZero();
  }
  // Outliers are not kept for the next frame's motion model.
  for (int i = 0; i < frame.size(); ++i) {
    if (frame.outlier[i]) frame.map_points[i] = nullptr;
  }
  last_frame_.emplace(std::move(frame));
  return result;
}

void Tracker::finish_tracked_frame(Frame& frame, TrackResult& result) {
  rolling_shutter_information_.setZero();
  const RollingShutterPose refined = refine_frame_rotation_rate(
      frame, options_.pose_optimizer, options_.rotation_rate_sigma, pose_buffers_);
  angular_velocity_ += refined.rate_correction;
  rolling_shutter_information_ = refined.pose_information;
  state_ = TrackingState::kOk;
  result.num_inliers = 0;
  for (int i = 0; i < frame.size(); ++i) {
    if (frame.map_points[i] && !frame.outlier[i]) ++result.num_inliers;
  }
  guard_against_movers(frame, result);
  maybe_insert_keyframe(frame, result);
}

void Tracker::on_lost(Frame& frame, TrackResult& result) {
  rolling_shutter_information_.setZero();
  state_ = TrackingState::kLost;
  result.method = TrackingMethod::kNone;
  frame.clear_pose();
  const bool young =
      map_.num_keyframes_in(map_.active_map()) <= initializer_->restart_when_lost_below();
  if (options_.new_map_after_seconds <= 0.0) {
    result.restart_due = young;
    return;
  }
  if (!lost_since_) {
    lost_since_ = frame.timestamp();
    initializer_->reset();
  }
  if (!young && frame.timestamp() - *lost_since_ < options_.new_map_after_seconds) {
    initializer_->observe(frame);  // the new map's start can place the frames lost meanwhile
    return;
  }
  // A new map in the atlas; the frames tracked so far stay in theirs, and the frames the
  // initialiser kept since the loss wait for it.
  forget_tracking_state(/*keep_initializer=*/true);
  ++map_epoch_;  // the new map has its own world frame: no correction is interpolated across
  map_.open_new_map();
  std::fill(frame.map_points.begin(), frame.map_points.end(), nullptr);
  std::fill(frame.outlier.begin(), frame.outlier.end(), 0);
  opening_new_map_ = true;
  start_map(frame, result);
}

bool Tracker::relocalize_in_atlas(Frame& frame) {
  if (!relocalizer_ || map_.num_keyframes() == 0) return false;
  if (relocalize(frame) && track_local_map(frame)) {
    initializer_->reset();
    opening_new_map_ = false;
    return true;
  }
  frame.clear_pose();
  std::fill(frame.map_points.begin(), frame.map_points.end(), nullptr);
  std::fill(frame.outlier.begin(), frame.outlier.end(), 0);
  reference_keyframe_.reset();
  return false;
}

bool Tracker::start_map(Frame& frame, TrackResult& result) {
  if (!initialize(frame, result)) return false;
  result.new_map = opening_new_map_;
  opening_new_map_ = false;
  state_ = TrackingState::kOk;
  result.method = TrackingMethod::kInitialization;
  result.keyframe_inserted = true;
  result.num_inliers = frame.size();
  return true;
}

Trajectory Tracker::refined_trajectory() const {
  std::vector<TrackedFramePose> frames;
  frames.reserve(anchors_.size());
  for (const FrameAnchor& anchor : anchors_) {
    TrackedFramePose& frame = frames.emplace_back();
    frame.timestamp = anchor.timestamp;
    frame.T_world_camera_tracked = anchor.T_camera_world.inverse();
    frame.map_epoch = anchor.map_epoch;
    const auto reference = anchor.reference.lock();
    const bool reference_alive = reference && !reference->is_bad();
    frame.T_world_camera_through_reference =
        reference_alive ? (anchor.T_camera_reference * reference->T_camera_world()).inverse()
                        : frame.T_world_camera_tracked;
    if (anchor.became_keyframe && reference_alive)
      frame.T_world_camera_keyframe_now = reference->T_world_camera();
  }
  return refine_by_keyframe_corrections(frames);
}

std::vector<std::uint32_t> Tracker::refined_map_ids() const {
  std::vector<std::uint32_t> ids;
  ids.reserve(anchors_.size());
  for (const FrameAnchor& anchor : anchors_) ids.push_back(map_.current_map_of(anchor.map_id));
  return ids;
}

void Tracker::on_map_corrected() {
  ++map_epoch_;
  if (anchors_.empty()) return;
  const FrameAnchor& anchor = anchors_.back();
  const auto reference = anchor.reference.lock();
  if (!reference || reference->is_bad()) return;
  const Pose corrected = orthonormalized(anchor.T_camera_reference * reference->T_camera_world());
  // The velocity is relative (T_current_last) and stays valid under a rigid correction. Under a
  // monocular loop's Sim(3) correction its translation (and the anchor's) keeps the old scale
  // for the next frame: off by the resize (a few per cent of a frame's motion), which that
  // frame's pose optimisation removes.
  last_tracked_pose_ = corrected;
  if (last_frame_ && last_frame_->has_pose()) last_frame_->set_pose(corrected);
}

std::optional<Pose> Tracker::last_tracked_world_pose() const {
  if (!last_tracked_pose_) return std::nullopt;
  return last_tracked_pose_->inverse();
}

bool Tracker::initialize(Frame& frame, TrackResult& result) {
  InitializationProgress progress;
  const std::vector<std::shared_ptr<KeyFrame>> keyframes =
      initializer_->initialize(frame, map_, progress);
  result.keypoints_with_depth = progress.keypoints_with_depth;
  result.keypoints_with_depth_needed = progress.keypoints_with_depth_needed;
  result.initialization_matches = progress.initialization_matches;
  result.initialization_model = progress.model;
  if (keyframes.empty()) return false;
  // Earlier frames the new map placed, anchored to the first keyframe like tracked frames to
  // their reference, so that the refined trajectory moves them with it.
  const std::shared_ptr<KeyFrame>& first = keyframes.front();
  for (const EarlierFramePose& earlier : initializer_->take_earlier_frames()) {
    result.earlier_frames.push_back({earlier.timestamp, earlier.T_camera_world.inverse()});
    anchors_.push_back({earlier.timestamp, first, earlier.T_camera_world * first->T_world_camera(),
                        earlier.T_camera_world, earlier.is_first_keyframe, map_epoch_,
                        first->map_id()});
  }
  reference_keyframe_ = keyframes.back();
  last_keyframe_ = reference_keyframe_;
  last_keyframe_frame_id_ = frame.id();
  local_map_.update(frame);
  if (sink_ != nullptr) {
    for (const auto& keyframe : keyframes) sink_->insert_keyframe(keyframe);
  }
  return true;
}

void Tracker::restart() {
  forget_tracking_state();
  anchors_.clear();
  ++restarts_;
}

void Tracker::forget_tracking_state(bool keep_initializer) {
  state_ = TrackingState::kNotInitialized;
  last_frame_.reset();
  velocity_.reset();
  angular_velocity_.setZero();
  motion_prior_.reset();
  last_tracked_pose_.reset();
  reference_keyframe_.reset();
  last_keyframe_.reset();
  last_keyframe_frame_id_ = 0;
  last_recovery_frame_id_ = 0;
  local_map_ = LocalMap(options_.max_local_keyframes);
  if (!keep_initializer) initializer_->reset();
  lost_since_.reset();
  predicted_pose_.reset();
  mover_guard_.reset();
}

void Tracker::replace_replaced_points(Frame& frame) const {
  for (auto& point : frame.map_points) {
    if (!point) continue;
    if (auto replacement = point->replaced_by()) point = replacement;
  }
}

int Tracker::discard_outliers(Frame& frame) {
  int matched_in_map = 0;
  for (int i = 0; i < frame.size(); ++i) {
    if (!frame.map_points[i]) continue;
    if (frame.outlier[i]) {
      frame.map_points[i] = nullptr;
      frame.outlier[i] = 0;
    } else if (frame.map_points[i]->num_observations() > 0) {
      ++matched_in_map;
    }
  }
  return matched_in_map;
}

std::optional<TrackedMotion> Tracker::tracked_motion(const Frame& frame) {
  std::shared_ptr<KeyFrame> previous = last_keyframe_.lock();
  if (!previous || previous->is_bad()) previous = reference_keyframe_;
  if (!previous || previous->is_bad()) return std::nullopt;
  TrackedMotion motion;
  motion.previous_keyframe_id = previous->id();
  motion.T_camera_previous = frame.T_camera_world() * previous->T_world_camera();
  // The rolling-shutter refinement ran last: its information, the rate marginalised, is the
  // pose's; a global shutter has only the pose-only optimisation's. Either way with the prior's.
  if (rolling_shutter_information_.isZero()) {
    motion.information = frame_pose_information(frame, options_.pose_optimizer, pose_buffers_,
                                                motion_prior_ ? &*motion_prior_ : nullptr);
  } else {
    motion.information = rolling_shutter_information_;
    if (motion_prior_) motion.information += prior_information(*motion_prior_);
  }
  return motion;
}

int Tracker::optimize_frame_pose(Frame& frame) {
  const PosePrior* prior = motion_prior_ ? &*motion_prior_ : nullptr;
  int set_aside = 0;
  const PoseOptimizationResult optimized =
      judged_through_frame_
          ? optimize_frame_pose_judged_first(frame, options_.pose_optimizer, pose_buffers_, prior,
                                             {.judged_through_frame = *judged_through_frame_,
                                              .min_points = options_.min_judged_points},
                                             set_aside)
          : pspslam::optimize_frame_pose(frame, options_.pose_optimizer, pose_buffers_, prior);
  unjudged_matches_set_aside_ = set_aside;  // the last solve's verdict is the frame's
  for (size_t k = 0; k < pose_buffers_.keypoint_of_observation.size(); ++k) {
    frame.outlier[pose_buffers_.keypoint_of_observation[k]] = optimized.inlier[k] ? 0 : 1;
  }
  return optimized.num_inliers;
}

bool Tracker::track_with_motion_model(Frame& frame) {
  frame.set_pose(orthonormalized(*velocity_ * last_frame_->T_camera_world()));
  predicted_pose_ = frame.T_camera_world();
  if (options_.motion_prior_sigma_rotation > 0.0 && options_.motion_prior_sigma_translation > 0.0)
    motion_prior_ = PosePrior{frame.T_camera_world(), options_.motion_prior_sigma_rotation,
                              options_.motion_prior_sigma_translation};
  std::fill(frame.map_points.begin(), frame.map_points.end(), nullptr);
  int matches =
      search_previous_frame(frame, *last_frame_, options_.motion_search_radius, options_.matcher);
  if (matches < options_.min_motion_matches) {
    std::fill(frame.map_points.begin(), frame.map_points.end(), nullptr);
    matches = search_previous_frame(frame, *last_frame_, 2.0 * options_.motion_search_radius,
                                    options_.matcher);
  }
  if (matches < options_.min_motion_matches) return false;
  optimize_frame_pose(frame);
  return discard_outliers(frame) >= options_.min_pose_inliers;
}

void Tracker::guard_against_movers(Frame& frame, TrackResult& result) {
  if (!options_.mover_guard.enabled) return;
  if (result.method != TrackingMethod::kMotionModel || !predicted_pose_) {
    mover_guard_.reset();
    return;
  }
  if (mover_guard_.should_hold(result.num_inliers, frame.T_camera_world(), *predicted_pose_)) {
    frame.set_pose(*predicted_pose_);
    result.pose_held = true;
  }
}

bool Tracker::track_reference_keyframe(Frame& frame, bool recovering) {
  if (!reference_keyframe_ || !last_tracked_pose_) return false;
  // After losing track, reference keyframe may have been replaced by a better one in local
  // mapping culling; fall back to the newest keyframe in the map in that case.
  if (reference_keyframe_->is_bad()) {
    const auto keyframes = map_.keyframes();
    if (keyframes.empty()) return false;
    reference_keyframe_ = keyframes.back();
  }
  std::fill(frame.map_points.begin(), frame.map_points.end(), nullptr);
  std::fill(frame.outlier.begin(), frame.outlier.end(), 0);
  MatcherOptions matcher = options_.matcher;
  matcher.nn_ratio = 0.7;  // stricter than projection: nothing constrains the match position
  const int matches = search_keyframe_brute_force(frame, *reference_keyframe_, matcher);
  if (matches < options_.min_reference_matches) return false;

  // After a loss the last pose may be stale: estimate one from the matches alone.
  if (recovering) {
    if (!pose_from_matches(frame)) return false;
  } else {
    frame.set_pose(*last_tracked_pose_);
  }
  optimize_frame_pose(frame);
  return discard_outliers(frame) >= options_.min_pose_inliers;
}

bool Tracker::relocalize(Frame& frame) {
  const RelocalizationResult relocalized = relocalizer_->relocalize(frame);
  if (!relocalized.success) return false;
  reference_keyframe_ = relocalized.keyframe;
  last_recovery_frame_id_ = frame.id();
  map_.set_active_map(reference_keyframe_->map_id());  // the atlas's map it found the camera in
  return true;
}

bool Tracker::track_local_map(Frame& frame) {
  if (auto reference = local_map_.update(frame)) reference_keyframe_ = reference;

  // Points already matched are not searched again; record that they were seen.
  const std::uint64_t frame_id = frame.id();
  for (int i = 0; i < frame.size(); ++i) {
    const auto& point = frame.map_points[i];
    if (!point) continue;
    if (point->is_bad()) {
      frame.map_points[i] = nullptr;
      continue;
    }
    point->increase_visible();
    point->last_seen_frame = frame_id;
  }
  projected_.clear();
  for (const auto& point : local_map_.points()) {
    if (point->last_seen_frame == frame_id || point->is_bad()) continue;
    ProjectedPoint p;
    if (project_map_point(point, frame, p)) {
      point->increase_visible();
      projected_.push_back(std::move(p));
    }
  }
  if (!projected_.empty()) {
    const bool just_recovered = frame.id() < last_recovery_frame_id_ + 2;
    search_by_projection(frame, projected_,
                         options_.local_map_search_radius * (just_recovered ? 5.0 / 3.0 : 1.0),
                         options_.matcher);
  }
  map_.set_reference_map_points(local_map_.points());

  optimize_frame_pose(frame);
  int inliers = 0;
  for (int i = 0; i < frame.size(); ++i) {
    const auto& point = frame.map_points[i];
    if (!point) continue;
    if (!frame.outlier[i]) {
      point->increase_found();
      if (point->num_observations() > 0) ++inliers;
    }
  }
  const bool recent_recovery =
      last_recovery_frame_id_ > 0 && frame.id() < last_recovery_frame_id_ + 30;
  const int needed = recent_recovery ? options_.min_local_map_inliers_after_recovery
                                     : options_.min_local_map_inliers;
  return inliers >= needed;
}

void Tracker::start_in_loaded_map() {
  if (!relocalizer_)
    throw Error("tracking in a loaded map needs relocalisation (a vocabulary); it is disabled");
  if (map_.num_keyframes() == 0) throw Error("tracking in a loaded map: the map is empty");
  state_ = TrackingState::kLost;
}

void Tracker::maybe_insert_keyframe(Frame& frame, TrackResult& result) {
  if (options_.localization_only) return;
  KeyFrameEvidence evidence;
  evidence.frame_id = frame.id();
  evidence.last_keyframe_frame_id = last_keyframe_frame_id_;
  evidence.last_relocalisation_frame_id = last_recovery_frame_id_;
  evidence.keyframes_in_map = static_cast<int>(map_.num_keyframes_in(map_.active_map()));
  evidence.tracked_inliers = result.num_inliers;
  const int min_observations = evidence.keyframes_in_map <= 2 ? 2 : 3;
  evidence.reference_tracked_points =
      reference_keyframe_ ? reference_keyframe_->tracked_map_points(min_observations) : 0;
  const double depth_threshold = frame.camera().depth_threshold;
  for (int i = 0; i < frame.size(); ++i) {
    const float z = frame.depth(i);
    if (z <= 0.0f || z >= depth_threshold) continue;
    if (frame.map_points[i] && !frame.outlier[i]) {
      ++evidence.tracked_close_points;
    } else {
      ++evidence.untracked_close_points;
    }
  }
  evidence.mapper_idle = sink_ == nullptr || sink_->accepts_keyframes();
  evidence.mapper_queue = sink_ == nullptr ? 0 : static_cast<int>(sink_->queued_keyframes());

  const KeyFrameDecision decision = decide_keyframe(evidence, options_.keyframes);
  if (decision == KeyFrameDecision::kSkip) return;
  if (sink_ != nullptr && decision != KeyFrameDecision::kInsert) {
    sink_->interrupt_bundle_adjustment();
  }
  if (decision == KeyFrameDecision::kInterruptMapper) return;
  const std::optional<TrackedMotion> motion = tracked_motion(frame);
  reference_keyframe_ = create_keyframe(frame, map_, /*initial=*/false, 100, motion);
  last_keyframe_ = reference_keyframe_;
  last_keyframe_frame_id_ = frame.id();
  result.keyframe_inserted = true;
  if (sink_ != nullptr) sink_->insert_keyframe(reference_keyframe_);
}

}  // namespace pspslam
