#include "pspslam/dynamic/dynamic_pipeline.h"

#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <span>
#include <utility>

#include "pspslam/core/clock.h"
#include "pspslam/core/error.h"
#include "pspslam/dynamic/keypoint_fusion.h"
#include "pspslam/geometry/compensated_homography.h"
#include "pspslam/io/image_files.h"
#include "pspslam/io/input_frame.h"
#include "pspslam/map/keyframe.h"
#include "pspslam/map/map.h"
#include "pspslam/map/map_point.h"
#include "pspslam/semantic/onnx_segmenter.h"
#include "pspslam/semantic/semantic_thread.h"

namespace pspslam {
namespace {

// The semantic thread of `options`: a live run that keeps pace gets the smaller network too and
// a SemanticPace over both; every other run one network on every frame it is given.
std::unique_ptr<SemanticThread> make_semantic_thread(const DynamicOptions& options,
                                                     const SemanticParams& params) {
  std::vector<std::unique_ptr<Segmenter>> segmenters;
  std::vector<double> costs;
  const auto add = [&](const std::filesystem::path& model) {
    auto segmenter = OnnxSegmenter::from_file(model);
    costs.push_back(static_cast<double>(segmenter->metadata().input_width) *
                    segmenter->metadata().input_height);
    segmenters.push_back(std::move(segmenter));
  };
  add(options.model);
  if (!options.realtime || !options.keep_pace)
    return std::make_unique<SemanticThread>(std::move(segmenters.front()), params);
  if (!options.smaller_model.empty()) add(options.smaller_model);
  SemanticPaceParams pace;
  pace.frame_period_ms = options.frame_period_ms;
  const int networks = static_cast<int>(segmenters.size());
  return std::make_unique<SemanticThread>(
      std::move(segmenters), params,
      SemanticPace(pace, pace_ladder(networks, std::max(1, options.pace_max_stride)), costs));
}

}  // namespace

const char* to_string(KeypointFate fate) {
  switch (fate) {
    case KeypointFate::tracked:
      return "tracked";
    case KeypointFate::unmatched:
      return "unmatched";
    case KeypointFate::semantic:
      return "semantic";
    case KeypointFate::geometry:
      return "geometry";
  }
  return "?";
}

DynamicPipeline::DynamicPipeline(const DynamicOptions& options, const PinholeCamera& camera,
                                 Map& map)
    : options_(options), camera_(camera), map_(map), culler_(options.culling) {
  GeometryParams geometry = options.geometry;
  if (options.mode == DynamicMode::full) geometry.search.strategy = SearchStrategy::ant_colony;
  if (options.mode == DynamicMode::exhaustive)
    geometry.search.strategy = SearchStrategy::exhaustive;
  if (uses_geometry(options.mode)) geometry_ = std::make_unique<GeometryStage>(camera, geometry);
  if (uses_semantics(options.mode) && options.semantic_masks.empty()) {
    SemanticParams params = options.semantic;
    // Deterministic mode announces one frame ahead: two may be pending and none may be
    // dropped. Real-time mode keeps only the newest pending frame.
    params.queue_size = options.realtime ? 1 : 2;
    semantic_ = make_semantic_thread(options, params);
    if (options.realtime && options.stale_masks == StaleMaskPolicy::flow)
      propagator_.emplace(camera.fx, options.frame_period_ms * 1e-3, options.propagation);
  }
}

// Out of line: SemanticThread is incomplete in the header.
DynamicPipeline::~DynamicPipeline() = default;

void DynamicPipeline::announce(const InputFrame& frame) {
  if (!semantic_) return;
  const std::int64_t id = next_announced_++;
  // With a stride the frames in between use the newest mask, warped (semantic_mask()). A live
  // run's stride may change under the pace: it counts from the last frame segmented.
  if (options_.realtime) {
    const int stride = std::max(options_.segment_every, semantic_->stride());
    if (last_segmented_ >= 0 && id - last_segmented_ < stride) return;
  } else if (id % options_.segment_every != 0) {
    return;
  }
  last_segmented_ = id;
  submitted_.push_back({id, frame.timestamp, std::chrono::steady_clock::now()});
  while (submitted_.size() > 64) submitted_.pop_front();
  semantic_->submit(id, frame.timestamp, frame.bgr);
}

cv::Mat DynamicPipeline::begin_frame(const InputFrame& frame, const cv::Mat& gray,
                                     DynamicReport& report) {
  current_id_ = next_id_++;
  labels_.release();
  watch_mask_.release();
  cull_mask_.release();
  if (semantic_ && next_announced_ <= current_id_) announce(frame);
  const auto start = std::chrono::steady_clock::now();
  H_previous_to_current_.reset();
  // The homographies also move an older mask into this frame (real time, or a stride).
  if (geometry_ || (semantic_ && (options_.realtime || options_.segment_every > 1))) {
    flow_.track(previous_gray_, gray, previous_points_);
    const CompensatedHomography H = estimate_compensated_homography(
        std::span<const Eigen::Vector2d>(flow_.matched_previous()),
        std::span<const Eigen::Vector2d>(flow_.matched_current()), options_.geometry.homography);
    if (H.valid) H_previous_to_current_ = H.H;
  }
  chain_.record(current_id_, H_previous_to_current_);
  if (propagator_) propagator_->add_frame(current_id_, gray, frame.depth);
  previous_gray_ = gray;
  report.flow_ms = milliseconds_since(start);
  if (semantic_) return semantic_mask(report);
  if (uses_semantics(options_.mode) && !options_.semantic_masks.empty())
    return mask_from_file(frame, report);
  return {};
}

cv::Mat DynamicPipeline::mask_from_file(const InputFrame& frame, DynamicReport& report) {
  const std::filesystem::path file = options_.semantic_masks / per_frame_png_name(frame.name);
  // Checked first: OpenCV would also print a warning of its own for a missing file.
  const cv::Mat image = std::filesystem::is_regular_file(file)
                            ? cv::imread(file.string(), cv::IMREAD_GRAYSCALE)
                            : cv::Mat();
  if (image.empty()) {
    throw Error(file.string() + ": no semantic mask for frame " + frame.name +
                " (--semantic-masks: an 8-bit PNG per frame, named after its colour image)");
  }
  if (image.size() != frame.bgr.size()) {
    throw Error(file.string() + ": the mask is " + std::to_string(image.cols) + "x" +
                std::to_string(image.rows) + " but frame " + frame.name + " is " +
                std::to_string(frame.bgr.cols) + "x" + std::to_string(frame.bgr.rows));
  }
  report.mask_age_frames = 0;
  labels_ = image;  // a `pspslam synth` mask/ image is a label map (15 = person)
  return dilate_mask(image != 0, options_.semantic.mask_dilation_px);
}

void DynamicPipeline::remove_dynamic(const cv::Mat& depth, std::span<const float> keypoint_depths,
                                     const cv::Mat& semantic_mask, OrbFeatures& features,
                                     DynamicReport& report, std::vector<KeypointRecord>* dropped) {
  geometry_mask_.release();
  picture_.regions.release();
  picture_.tested.clear();
  picture_.path.clear();
  const std::vector<std::uint8_t>* geometry_flags = nullptr;
  if (geometry_ && prior_pose()) collect_reference_views();
  if (geometry_ && prior_pose() && !views_.empty()) {
    const auto start = std::chrono::steady_clock::now();
    pixels_.resize(features.keypoints.size());
    // Distorted pixel positions: the depth image is registered to the distorted image, and
    // the lens distortion of Kinect-class presets moves pixels by less than the test's patch.
    for (size_t i = 0; i < features.keypoints.size(); ++i)
      pixels_[i] = {features.keypoints[i].pt.x, features.keypoints[i].pt.y};
    GeometryFrameInput input;
    input.depth = depth;
    input.T_world_camera = *prior_pose();
    input.keypoints = pixels_;
    input.keypoint_depths = keypoint_depths;
    input.references = views_;
    // The stage maps each keypoint back through the flow step's H into the previous mask, so
    // the mask needs no full-image warp here.
    if (!watch_mask_.empty()) {
      // A stale mask: the prior is already in this frame (no homography to map back through).
      input.previous_dynamic_mask = watch_mask_;
      report.geometry_tightened = true;
    } else if (!previous_mask_.empty() && H_previous_to_current_) {
      input.previous_dynamic_mask = previous_mask_;
      input.H_previous_to_current = H_previous_to_current_;
    }
    GeometryFrameResult result = geometry_->process(input);
    report.geometry_ms = milliseconds_since(start);
    report.geometry_search_ms = result.timing.search_ms;
    report.geometry_ran = true;
    report.tested_points = result.tested_count;
    report.dynamic_points = result.dynamic_count;
    geometry_flags_ = std::move(result.keypoint_dynamic);
    geometry_flags = &geometry_flags_;
    geometry_mask_ = std::move(result.dynamic_mask);
    if (dropped) {
      // Copies, only for pictures: the stage reuses its buffers on the next frame.
      picture_.regions = geometry_mask_.clone();
      for (size_t i = 0; i < result.keypoint_tested.size(); ++i) {
        if (result.keypoint_tested[i])
          picture_.tested.push_back(
              {features.keypoints[i].pt, result.keypoint_tested_dynamic[i] != 0});
      }
      for (const Eigen::Vector2f& node : geometry_->last_search_path())
        picture_.path.emplace_back(node.x(), node.y());
    }
  }
  fuse_keypoint_flags(features.keypoints, semantic_mask,
                      geometry_flags ? std::span<const std::uint8_t>(*geometry_flags)
                                     : std::span<const std::uint8_t>(),
                      dynamic_flags_);
  if (dropped) {
    // The same precedence as fuse_keypoint_flags(): a geometry flag first, else the mask.
    for (size_t i = 0; i < features.keypoints.size(); ++i) {
      if (!dynamic_flags_[i]) continue;
      const bool by_geometry = geometry_flags != nullptr && (*geometry_flags)[i] != 0;
      dropped->push_back({features.keypoints[i].pt,
                          by_geometry ? KeypointFate::geometry : KeypointFate::semantic});
    }
  }
  report.masked_keypoints =
      remove_flagged_keypoints(dynamic_flags_, features.keypoints, features.descriptors);
  // Static keypoints of this frame seed the next frame's optical flow.
  previous_points_.clear();
  for (const cv::KeyPoint& keypoint : features.keypoints) previous_points_.push_back(keypoint.pt);
}

void DynamicPipeline::use_loaded_map_only() {
  protect_map_ = true;
  if (geometry_) map_references_.emplace(map_, camera_);
}

void DynamicPipeline::reanchor_last_pose(const std::optional<Pose>& T_world_camera) {
  if (last_pose_ && T_world_camera) last_pose_ = T_world_camera;
}

void DynamicPipeline::end_frame(const TrackResult& result, const cv::Mat& depth,
                                const cv::Mat& semantic_mask, DynamicReport& report) {
  previous_mask_ = fuse_dynamic_masks(semantic_mask, geometry_mask_, 0);
  remember_segmented_frame(result, depth, report);
  if (result.keyframe_inserted && geometry_) {
    if (auto keyframe = map_.keyframe(map_.max_keyframe_id())) {
      // The depth Mat is shared, not copied: frames are loaded fresh and never written to.
      references_.push_front({keyframe, depth});
      // A pool larger than the views the test uses: the stage picks them by coverage of the
      // frame (reference_selection.h), so a camera turn does not leave the image edge unseen.
      const size_t keep = kReferencePoolFactor *
                          static_cast<size_t>(options_.geometry.multiview.max_reference_views);
      while (references_.size() > keep) references_.pop_back();
    }
  }
  if (result.T_world_camera) {
    // A frame that started a map is in a new world frame: no velocity across it.
    if (last_pose_ && last_pose_id_ + 1 == current_id_ &&
        result.method != TrackingMethod::kInitialization) {
      velocity_ = last_pose_->inverse() * *result.T_world_camera;  // T_last_current
    } else {
      velocity_.reset();
    }
    last_pose_ = result.T_world_camera;
    last_pose_id_ = current_id_;
    if (!protect_map_)
      report.culled_map_points += cull_frame(*result.T_world_camera, depth, report);
  }
}

// Step 6 for one view (pose, dynamic mask, depth): the local map's points seen on its dynamic
// pixels count towards their culling; those that reach the threshold leave the map. Returns how
// many did.
int DynamicPipeline::cull(const Pose& T_world_camera, const cv::Mat& mask, const cv::Mat& depth) {
  const auto points = map_.reference_map_points();
  const auto& culled = culler_.observe(points, T_world_camera, mask, depth, camera_);
  if (!culled.empty()) {
    std::lock_guard lock(map_.update_mutex());
    for (const auto& point : culled) map_.erase_map_point(point);
  }
  return static_cast<int>(culled.size());
}

// Step 6 for this frame, by the run's culling evidence: what its depth sees through, or its
// culling mask; nothing when culling is off (no mask is fused for it then).
int DynamicPipeline::cull_frame(const Pose& T_world_camera, const cv::Mat& depth,
                                const DynamicReport& report) {
  switch (options_.culling.evidence) {
    case CullingEvidence::none:
      return 0;
    case CullingEvidence::seen_through:
      return cull(T_world_camera, {}, depth);
    case CullingEvidence::dynamic_pixels:
      break;
  }
  const cv::Mat mask = culling_mask(report);
  return mask.empty() ? 0 : cull(T_world_camera, mask, depth);
}

// A live run culling on exact masks only, whose mask for this frame is stale: only late masks,
// each at its own frame, judge the map's points.
bool DynamicPipeline::judged_by_late_masks_only(const DynamicReport& report) const {
  return options_.realtime && options_.cull_with_late_masks &&
         report.mask_age_frames > options_.stale_mask_frames;
}

std::optional<int> DynamicPipeline::frames_since_judged(const DynamicReport& report) const {
  if (protect_map_ || !judged_by_late_masks_only(report)) return std::nullopt;
  return report.mask_age_frames;
}

// The pixels whose map points count towards culling in this frame.
cv::Mat DynamicPipeline::culling_mask(const DynamicReport& report) const {
  // A stale mask lies where the people were: the static points they uncovered since would be
  // culled by it. Its own frame judges it when it arrives (judge_late_frame); here only this
  // frame's geometry verdicts count.
  if (judged_by_late_masks_only(report)) return geometry_mask_;
  return cull_mask_.empty() ? previous_mask_ : fuse_dynamic_masks(cull_mask_, geometry_mask_, 0);
}

cv::Mat DynamicPipeline::semantic_mask(DynamicReport& report) {
  std::shared_ptr<const SemanticResult> result;
  if (!options_.realtime) {
    const auto start = std::chrono::steady_clock::now();
    // The newest frame segmented at or before this one (this one without a stride).
    const std::int64_t segmented = current_id_ - current_id_ % options_.segment_every;
    result = semantic_->wait_for(segmented, options_.semantic_timeout);
    report.semantic_wait_ms = milliseconds_since(start);
  }
  if (!result) result = semantic_->newest();
  if (options_.realtime && options_.keep_pace) report.semantic_pace_level = semantic_->level();
  if (!result || result->frame_id > current_id_) return {};
  if (options_.realtime && options_.cull_with_late_masks) judge_late_frame(*result, report);
  cv::Mat mask;
  if (propagator_) {
    mask = propagate_mask(*result, report);
  } else {
    const WarpedMask warped =
        warp_mask_to_frame(result->dynamic_mask, result->frame_id, current_id_, chain_);
    report.mask_age_frames = warped.age_frames;
    report.mask_warped = warped.warped;
    mask = warped.mask;
  }
  if (mask.empty()) return {};
  report.semantic_inference_ms = result->inference_ms;
  if (options_.realtime && options_.keep_pace) report.semantic_level = result->level;
  labels_ = result->labels;
  for (const Submitted& submitted : submitted_) {
    if (submitted.id == result->frame_id)
      report.mask_latency_ms = milliseconds_since(submitted.time);
  }
  return mask;
}

void DynamicPipeline::judge_late_frame(const SemanticResult& result, DynamicReport& report) {
  const std::optional<SegmentedFrame> frame = late_mask_frames_.take(result.frame_id);
  if (!frame || protect_map_ || frame->map_id != map_.active_map()) return;
  report.late_frame_judged = true;
  // Seen-through evidence judged that frame when it was tracked; a mask adds nothing to it.
  if (options_.culling.evidence != CullingEvidence::dynamic_pixels) return;
  report.culled_by_late_mask = cull(frame->T_world_camera, result.dynamic_mask, frame->depth);
  report.culled_map_points += report.culled_by_late_mask;
}

void DynamicPipeline::remember_segmented_frame(const TrackResult& result, const cv::Mat& depth,
                                               const DynamicReport& report) {
  if (!options_.realtime || !options_.cull_with_late_masks || !semantic_) return;
  if (last_segmented_ != current_id_ || !result.T_world_camera || depth.empty()) return;
  if (report.mask_age_frames == 0) return;  // its own mask came in time and was used
  late_mask_frames_.remember({current_id_, map_.active_map(), *result.T_world_camera, depth});
}

cv::Mat DynamicPipeline::propagate_mask(const SemanticResult& result, DynamicReport& report) {
  const bool stale = current_id_ - result.frame_id > options_.stale_mask_frames;
  PropagatedMask moved = propagator_->propagate(result.dynamic_mask, result.frame_id, current_id_,
                                                chain_, stale && options_.tighten_geometry);
  report.mask_age_frames = moved.age_frames;
  report.mask_warped = moved.age_frames > 0;
  report.mask_moved_by_flow = moved.moved_by_flow > 0;
  report.mask_growth_px = moved.growth_px;
  if (stale && options_.tighten_geometry) watch_mask_ = std::move(moved.watch);
  // Map points are culled on the people's moved outline: the growth is a margin of doubt, and
  // static points inside it must not be erased for it.
  cull_mask_ = std::move(moved.moved);
  return moved.mask;
}

// The geometry stage's reference pool: the depth images of this run's newest keyframes, or in
// localisation the loaded map's keyframes nearest the pose prior.
void DynamicPipeline::collect_reference_views() {
  views_.clear();
  const size_t pool_size =
      kReferencePoolFactor * static_cast<size_t>(options_.geometry.multiview.max_reference_views);
  if (map_references_) {
    map_references_->pool(*prior_pose(), pool_size, views_);
    return;
  }
  // Keyframes of another map of the atlas are in another world frame.
  const std::uint32_t active_map = map_.active_map();
  for (const auto& reference : references_) {
    const auto keyframe = reference.keyframe.lock();
    if (keyframe && !keyframe->is_bad() && keyframe->map_id() == active_map)
      views_.push_back({keyframe->T_world_camera(), reference.depth});
  }
}

std::optional<Pose> DynamicPipeline::prior_pose() const {
  if (!last_pose_ || last_pose_id_ + 1 != current_id_) return std::nullopt;
  // Constant velocity, as tracking's own motion model.
  return velocity_ ? *last_pose_ * *velocity_ : *last_pose_;
}

}  // namespace pspslam
