#include "pspslam/tracking/map_initializer.h"

#include <algorithm>
#include <climits>
#include <deque>
#include <optional>

#include "pspslam/map/descriptor.h"
#include "pspslam/map/frame.h"
#include "pspslam/map/keyframe.h"
#include "pspslam/map/map.h"
#include "pspslam/map/map_point.h"
#include "pspslam/match/orb_matcher.h"
#include "pspslam/optimize/global_bundle_adjustment.h"
#include "pspslam/tracking/frame_pose_optimization.h"
#include "pspslam/tracking/keyframe_builder.h"

namespace pspslam {
namespace {

// Tracking's minimum of local-map inliers (TrackerOptions::min_local_map_inliers).
constexpr int kMinPlacedInliers = 30;
// Lost frames kept for a new map: 3 s at 30 fps (MonocularInitializerOptions::max_earlier_frames).
constexpr size_t kMaxKeptLostFrames = 90;

// A lost frame placed on a new map's keyframe as tracking recovers a lost frame: brute-force
// matches with the keyframe's points, PnP-RANSAC, pose-only optimisation. False when too few
// inliers remain (black, or looking elsewhere).
bool place_on_keyframe(Frame& lost, const KeyFrame& keyframe,
                       const PoseOptimizerOptions& pose_optimizer, FramePoseBuffers& buffers) {
  MatcherOptions matcher;
  matcher.nn_ratio = 0.7;  // nothing constrains where a match may be: the recovery's ratio
  std::fill(lost.map_points.begin(), lost.map_points.end(), nullptr);
  if (search_keyframe_brute_force(lost, keyframe, matcher) < kMinPlacedInliers) return false;
  if (!pose_from_matches(lost)) return false;
  return optimize_frame_pose(lost, pose_optimizer, buffers).num_inliers >= kMinPlacedInliers;
}

// A lost frame as kept for a new map: without what tracking matched it to in the old map.
void keep_lost_frame(const Frame& frame, std::deque<Frame>& kept) {
  if (kept.size() == kMaxKeptLostFrames) kept.pop_front();
  Frame& copy = kept.emplace_back(frame);
  copy.clear_pose();
  std::fill(copy.map_points.begin(), copy.map_points.end(), nullptr);
  std::fill(copy.outlier.begin(), copy.outlier.end(), 0);
}

class DepthMapInitializer final : public MapInitializer {
 public:
  DepthMapInitializer(int min_points, PoseOptimizerOptions pose_optimizer)
      : min_points_(min_points), pose_optimizer_(std::move(pose_optimizer)) {}

  std::vector<std::shared_ptr<KeyFrame>> initialize(Frame& frame, Map& map,
                                                    InitializationProgress& progress) override {
    int with_depth = 0;
    for (int i = 0; i < frame.size(); ++i) with_depth += frame.depth(i) > 0.0f ? 1 : 0;
    progress.keypoints_with_depth = with_depth;
    progress.keypoints_with_depth_needed = min_points_;
    if (with_depth < min_points_) return {};
    // The first camera defines the world frame.
    frame.set_pose(Pose::Identity());
    const std::shared_ptr<KeyFrame> first = create_keyframe(frame, map, /*initial=*/true);
    place_lost_frames(*first);
    return {first};
  }

  void observe(const Frame& frame) override { keep_lost_frame(frame, lost_); }

  std::vector<EarlierFramePose> take_earlier_frames() override { return std::move(earlier_); }

  void reset() override {
    lost_.clear();
    earlier_.clear();
  }

 private:
  // A new map of the atlas starts with the frames lost before it still kept (observe), each
  // placed on its first keyframe.
  void place_lost_frames(const KeyFrame& first) {
    earlier_.clear();
    for (Frame& lost : lost_) {
      if (place_on_keyframe(lost, first, pose_optimizer_, pose_buffers_))
        earlier_.push_back({lost.timestamp(), lost.T_camera_world(), /*is_first_keyframe=*/false});
    }
    lost_.clear();
  }

  int min_points_;
  PoseOptimizerOptions pose_optimizer_;
  std::deque<Frame> lost_;                 // oldest first
  std::vector<EarlierFramePose> earlier_;  // placed by the last start, oldest first
  FramePoseBuffers pose_buffers_;
};

class MonocularMapInitializer final : public MapInitializer {
 public:
  explicit MonocularMapInitializer(MonocularInitializerOptions options)
      : options_(std::move(options)) {}

  std::vector<std::shared_ptr<KeyFrame>> initialize(Frame& frame, Map& map,
                                                    InitializationProgress& progress) override {
    if (frame.size() < options_.min_keypoints) {
      reset();
      return {};
    }
    if (!reference_) {
      take_as_reference(frame);
      return {};
    }
    const int matches = match_with_reference(frame);
    progress.initialization_matches = matches;
    if (matches < options_.min_matches) {
      take_as_reference(frame);
      return {};
    }
    first_pixels_.clear();
    second_pixels_.clear();
    match_index_.clear();
    for (int i = 0; i < reference_->size(); ++i) {
      const int j = match_of_reference_[static_cast<size_t>(i)];
      if (j < 0) continue;
      const cv::Point2f& a = reference_->keypoints()[i].pt;
      const cv::Point2f& b = frame.keypoints()[j].pt;
      first_pixels_.emplace_back(a.x, a.y);
      second_pixels_.emplace_back(b.x, b.y);
      match_index_.push_back(i);
    }
    const TwoViewResult two_view = initialize_two_view(frame.camera().pinhole, first_pixels_,
                                                       second_pixels_, options_.two_view);
    progress.model = two_view.model;
    if (!two_view.success) {
      remember_between(frame);
      return {};
    }
    std::vector<std::shared_ptr<KeyFrame>> keyframes = build_map(frame, map, two_view);
    if (keyframes.empty()) {
      // Only the map this start made goes; the atlas's other maps stay.
      if (map.map_ids().size() <= 1) {
        map.clear();
      } else {
        map.erase_map(map.active_map());
      }
      frame.clear_pose();
      std::fill(frame.map_points.begin(), frame.map_points.end(), nullptr);
      take_as_reference(frame);
    } else {
      localise_between(*keyframes.front());
      place_lost_frames(*keyframes.front());
      reference_.reset();
    }
    return keyframes;
  }

  void observe(const Frame& frame) override {
    if (frame.size() < options_.min_keypoints) {
      reference_.reset();
      between_.clear();
      return;
    }
    keep_lost_frame(frame, lost_);
    if (!reference_ || match_with_reference(frame) < options_.min_matches) {
      take_as_reference(frame);
    } else {
      remember_between(frame);
    }
  }

  std::vector<EarlierFramePose> take_earlier_frames() override { return std::move(earlier_); }

  std::size_t restart_when_lost_below() const override { return options_.restart_when_lost_below; }
  void reset() override {
    reference_.reset();
    between_.clear();
    earlier_.clear();
    lost_.clear();
  }

 private:
  // A frame matched with the reference that did not start the map: kept with its matches so that
  // the map, once started, can place it.
  struct FrameBetween {
    Frame frame;
    std::vector<int> match_of_reference;
  };

  void remember_between(const Frame& frame) {
    if (between_.size() >= options_.max_earlier_frames) return;
    between_.push_back({frame, match_of_reference_});
  }

  // The reference (the first keyframe, at the origin) and the frames kept since it, each from the
  // pose of the one before: a pose-only optimisation on the first keyframe's points its
  // reference matches reached, as tracking does with its matches (outliers by the same chi2
  // rounds). A frame that keeps too few inliers stays without a pose.
  void localise_between(const KeyFrame& first) {
    earlier_.clear();
    earlier_.push_back({reference_->timestamp(), Pose::Identity(), /*is_first_keyframe=*/true});
    Pose previous = Pose::Identity();
    for (FrameBetween& between : between_) {
      Frame& frame = between.frame;
      std::fill(frame.map_points.begin(), frame.map_points.end(), nullptr);
      int matched = 0;
      for (size_t i = 0; i < between.match_of_reference.size(); ++i) {
        const int j = between.match_of_reference[i];
        if (j < 0) continue;
        std::shared_ptr<MapPoint> point = first.map_point(static_cast<int>(i));
        if (!point || point->is_bad()) continue;
        frame.map_points[static_cast<size_t>(j)] = std::move(point);
        ++matched;
      }
      if (matched < options_.min_earlier_frame_inliers) continue;
      frame.set_pose(previous);
      const PoseOptimizationResult optimized =
          optimize_frame_pose(frame, options_.pose_optimizer, pose_buffers_);
      if (optimized.num_inliers < options_.min_earlier_frame_inliers) continue;
      previous = frame.T_camera_world();
      earlier_.push_back({frame.timestamp(), previous, /*is_first_keyframe=*/false});
    }
    between_.clear();
  }

  // A new map of the atlas: the frames lost before its reference view (a fast turn makes the
  // start take new references, and the frames before the last one are not between its views),
  // each placed on the first keyframe's points.
  void place_lost_frames(const KeyFrame& first) {
    const Timestamp reference_time = earlier_.front().timestamp;
    for (Frame& lost : lost_) {
      if (lost.timestamp() >= reference_time) break;
      if (place_on_keyframe(lost, first, options_.pose_optimizer, pose_buffers_))
        earlier_.push_back({lost.timestamp(), lost.T_camera_world(), /*is_first_keyframe=*/false});
    }
    lost_.clear();
    std::sort(earlier_.begin(), earlier_.end(),
              [](const auto& a, const auto& b) { return a.timestamp < b.timestamp; });
  }

  void take_as_reference(const Frame& frame) {
    between_.clear();
    reference_.emplace(frame);
    last_position_.resize(static_cast<size_t>(frame.size()));
    for (int i = 0; i < frame.size(); ++i)
      last_position_[static_cast<size_t>(i)] = frame.keypoints()[i].pt;
  }

  // ORB-SLAM's SearchForInitialization: each keypoint of the reference is looked for among the
  // frame's keypoints around where it was last matched (the camera moves little between frames),
  // best distance under TH_LOW passing the ratio test, one-to-one, rotation-consistent. ORB-SLAM
  // takes the finest level only, from an extractor with twice the features during
  // initialisation; with one extractor of n_features (1000: ~220 at level 0) that left ~100
  // matches on the synthetic sequence, too few to keep a reference, so every level is matched
  // against the frame's keypoints one level either side. Fills match_of_reference_ (frame index
  // or -1); returns the count.
  int match_with_reference(const Frame& frame) {
    const Frame& reference = *reference_;
    match_of_reference_.assign(static_cast<size_t>(reference.size()), -1);
    distance_of_frame_.assign(static_cast<size_t>(frame.size()), INT_MAX);
    reference_of_frame_.assign(static_cast<size_t>(frame.size()), -1);
    RotationHistogram histogram;
    int matches = 0;
    for (int i = 0; i < reference.size(); ++i) {
      const cv::KeyPoint& keypoint = reference.keypoints()[i];
      const cv::Point2f& centre = last_position_[static_cast<size_t>(i)];
      frame.features_in_area(centre.x, centre.y, options_.search_radius_px,
                             std::max(0, keypoint.octave - 1), keypoint.octave + 1, candidates_);
      int best = INT_MAX, second = INT_MAX, best_index = -1;
      for (const int j : candidates_) {
        const int distance = descriptor_distance(reference.descriptor(i), frame.descriptor(j));
        if (distance_of_frame_[static_cast<size_t>(j)] <= distance) continue;
        if (distance < best) {
          second = best;
          best = distance;
          best_index = j;
        } else if (distance < second) {
          second = distance;
        }
      }
      if (best_index < 0 || best > options_.max_descriptor_distance) continue;
      if (best >= options_.nn_ratio * second) continue;
      const size_t j = static_cast<size_t>(best_index);
      if (reference_of_frame_[j] >= 0) {  // the frame keypoint had a worse partner: replace it
        match_of_reference_[static_cast<size_t>(reference_of_frame_[j])] = -1;
        --matches;
      }
      match_of_reference_[static_cast<size_t>(i)] = best_index;
      reference_of_frame_[j] = i;
      distance_of_frame_[j] = best;
      ++matches;
    }
    for (int i = 0; i < reference.size(); ++i) {
      const int j = match_of_reference_[static_cast<size_t>(i)];
      if (j >= 0) histogram.add(reference.keypoints()[i].angle, frame.keypoints()[j].angle, i);
    }
    for (const int i : histogram.rejected()) {
      match_of_reference_[static_cast<size_t>(i)] = -1;
      --matches;
    }
    for (int i = 0; i < reference.size(); ++i) {
      const int j = match_of_reference_[static_cast<size_t>(i)];
      if (j >= 0) last_position_[static_cast<size_t>(i)] = frame.keypoints()[j].pt;
    }
    return matches;
  }

  // The reference and `frame` become keyframes 0 and 1 with the triangulated points, bundle
  // adjusted together, then scaled to a median depth of 1 in keyframe 0 (ORB-SLAM's
  // CreateInitialMapMonocular). Empty (and the map left for the caller to clear) when the
  // adjusted map is unusable.
  std::vector<std::shared_ptr<KeyFrame>> build_map(Frame& frame, Map& map,
                                                   const TwoViewResult& two_view) {
    Frame& reference = *reference_;
    reference.set_pose(Pose::Identity());
    frame.set_pose(two_view.T_second_first);
    std::fill(reference.map_points.begin(), reference.map_points.end(), nullptr);
    std::fill(frame.map_points.begin(), frame.map_points.end(), nullptr);
    const auto first = create_keyframe(reference, map, /*initial=*/true);
    const auto second = create_keyframe(frame, map, /*initial=*/true);
    for (size_t k = 0; k < match_index_.size(); ++k) {
      if (!two_view.triangulated[k]) continue;
      const int i = match_index_[k];
      const int j = match_of_reference_[static_cast<size_t>(i)];
      // World = the first camera.
      auto point = std::make_shared<MapPoint>(map.next_map_point_id(), two_view.points[k], first);
      point->add_observation(first, i);
      point->add_observation(second, j);
      first->add_map_point(i, point);
      second->add_map_point(j, point);
      point->compute_distinctive_descriptor();
      point->update_normal_and_depth(frame.pyramid());
      map.add_map_point(point);
      frame.map_points[j] = point;
    }
    first->update_connections();
    second->update_connections();

    GlobalBaOptions ba;
    ba.iterations = options_.bundle_adjustment_iterations;
    ba.map_id = first->map_id();
    const GlobalBaResult adjusted = solve_global_bundle_adjustment(map, ba);
    if (adjusted.completed) apply_global_bundle_adjustment(map, adjusted);

    // Median depth of the points in the first camera; the second must still see enough.
    std::vector<double> depths;
    int tracked = 0;
    for (const auto& point : first->map_points()) {
      if (!point || point->is_bad()) continue;
      depths.push_back(point->position().z());  // first camera = world
    }
    for (const auto& point : second->map_points()) tracked += point && !point->is_bad() ? 1 : 0;
    if (depths.empty()) return {};
    std::nth_element(depths.begin(), depths.begin() + static_cast<long>(depths.size() / 2),
                     depths.end());
    const double median_depth = depths[depths.size() / 2];
    if (!(median_depth > 0.0) || tracked < options_.min_map_points) return {};

    const double scale = 1.0 / median_depth;
    Pose T_second_world = second->T_camera_world();
    T_second_world.translation() *= scale;
    second->set_pose(T_second_world);
    for (const auto& point : first->map_points()) {
      if (!point) continue;
      point->set_position(point->position() * scale);
      point->update_normal_and_depth(frame.pyramid());
    }
    frame.set_pose(T_second_world);
    for (int j = 0; j < frame.size(); ++j) frame.map_points[j] = second->map_point(j);
    return {first, second};
  }

  MonocularInitializerOptions options_;
  std::optional<Frame> reference_;
  std::vector<FrameBetween> between_;      // matched with reference_ since it was taken
  std::vector<EarlierFramePose> earlier_;  // placed by the last successful start
  std::deque<Frame> lost_;                 // a new map's lost frames so far (observe), oldest first
  FramePoseBuffers pose_buffers_;
  std::vector<cv::Point2f> last_position_;  // per reference keypoint
  // Per-attempt buffers, reused.
  std::vector<int> match_of_reference_;
  std::vector<int> reference_of_frame_;
  std::vector<int> distance_of_frame_;
  std::vector<int> candidates_;
  std::vector<int> match_index_;  // per correspondence: reference keypoint
  std::vector<Eigen::Vector2d> first_pixels_;
  std::vector<Eigen::Vector2d> second_pixels_;
};

}  // namespace

std::unique_ptr<MapInitializer> make_depth_map_initializer(int min_points,
                                                           PoseOptimizerOptions pose_optimizer) {
  return std::make_unique<DepthMapInitializer>(min_points, std::move(pose_optimizer));
}

std::unique_ptr<MapInitializer> make_monocular_map_initializer(
    MonocularInitializerOptions options) {
  return std::make_unique<MonocularMapInitializer>(std::move(options));
}

}  // namespace pspslam
