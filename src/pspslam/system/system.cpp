// Thread layout of the SLAM system (PSPNet-SLAM, paper Fig. 1). System owns every thread object;
// the dynamic-scene steps 1, 2, 4 and 6 below are DynamicPipeline (dynamic/dynamic_pipeline.h),
// which System drives on the caller thread and which owns the semantic thread. Frames come from
// the caller: `pspslam run` feeds a recorded sequence through SequenceRunner (session/).
//
//   semantic thread         SemanticThread (semantic/): one Segmenter (our PSPNet over ONNX);
//     (modes semantic,        frames are announce()d ahead of process(), so the network works on
//      full, exhaustive)      frame i+1 while the caller tracks frame i; publishes label maps and
//                             dilated dynamic-class masks by frame id
//                                  | newest / own-frame mask
//                                  v
//   caller thread           System::process(), per frame, in this order (steps 1, 2, 4, 6:
//                             DynamicPipeline::begin_frame / remove_dynamic / end_frame):
//                             1. LK flow previous -> current frame and the compensated
//                                homography H (eq. 10-11); recorded in a HomographyChain
//                             2. semantic mask: deterministic = wait for this frame's own mask;
//                                --realtime = never wait, take the newest mask and warp it
//                                through the chained H of the frames since (mask_warper.h)
//                             3. ORB extraction with the semantic mask as extraction mask (no
//                                features on people), then the Frame is built
//                             4. geometry stage (geometry/) on the extracted keypoints: pose prior
//                                = constant-velocity prediction from the last two tracked poses,
//                                references = depth images of the newest keyframes, priority =
//                                previous fused mask warped by H; the search is the ant colony
//                                (full) or every point (exhaustive); flagged keypoints and those
//                                inside grown regions are dropped *before* the Frame exists, so
//                                they are neither tracked nor turned into map points
//                             5. Tracker::track() (holds Map::update_mutex() while it works);
//                                deterministic runs first wait until local mapping, loop closing
//                                and any global BA are idle, so the map a frame meets does not
//                                depend on the machine's speed
//                             6. map points of the local map that project onto the fused mask
//                                with matching depth are counted; repeat offenders are erased
//                                  | KeyFrameSink::insert_keyframe (keyframe already in Map)
//                                  v
//   local mapping thread    LocalMapping (mapping/): queue of keyframes; per keyframe point
//                             culling, triangulation, fusion, local BA, keyframe culling; it
//                             takes Map::update_mutex() while it writes BA results back
//                                  | LocalMapping::set_keyframe_listener (processed keyframes)
//                                  v
//   loop closing thread     LoopClosing (loop/): BoW detection with covisibility consistency,
//                             3D-3D RANSAC verification; for a loop: stops local mapping,
//                             correct_loop() under Map::update_mutex() (fusion, essential
//                             graph), re-anchors the tracker, releases local mapping
//   global BA thread        started after each loop: solves on a snapshot, writes back under
//                             Map::update_mutex() with local mapping stopped (docs/loop_closing.md)
//
// Why geometry runs on the caller thread, after extraction and before tracking: it needs the
// frame's keypoints (extraction) and a pose (the motion-model prior is good to a few cm at 30 Hz,
// and the multi-view test's patch absorbs that), and its verdict must be in before tracking so
// that dynamic features never touch the map. A separate thread would only wait for extraction
// and then make tracking wait for it; on a 2-core machine shared with the semantic network there
// is no idle core to win. The first frames (no prior, no keyframe yet) run without geometry.
#include "pspslam/system/system.h"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <limits>
#include <mutex>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <vector>

#include "pspslam/core/clock.h"
#include "pspslam/dynamic/dynamic_pipeline.h"
#include "pspslam/feature/orb_extractor.h"
#include "pspslam/io/input_frame.h"
#include "pspslam/loop/loop_closing.h"
#include "pspslam/map/camera_model.h"
#include "pspslam/map/frame.h"
#include "pspslam/map/keyframe.h"
#include "pspslam/map/map.h"
#include "pspslam/map/map_point.h"
#include "pspslam/map/scale_pyramid.h"
#include "pspslam/mapping/local_mapping.h"
#include "pspslam/persistence/map_file.h"
#include "pspslam/place/place_recognition.h"
#include "pspslam/system/frame_builder.h"
#include "pspslam/tracking/keyframe_sink.h"

namespace pspslam {
namespace {

double thread_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
}

}  // namespace

// Connects tracking's KeyFrameSink to the local mapping thread (or to nothing when local
// mapping is off: keyframes are then complete in the map, just never refined) and keeps the
// run statistics that LocalMapping does not (queue high-water mark, BA time).
class System::MappingConnection final : public KeyFrameSink {
 public:
  MappingConnection(std::unique_ptr<LocalMapping> mapping, std::shared_ptr<PlaceRecognition> place)
      : mapping_(std::move(mapping)), place_(std::move(place)) {}

  void insert_keyframe(std::shared_ptr<KeyFrame> keyframe) override {
    if (!mapping_) {
      // No local mapping to index the keyframe: do it here so relocalisation still works.
      if (place_) {
        keyframe->compute_bow(place_->vocabulary(), place_->direct_index_level());
        place_->database().add(keyframe->id(), keyframe->bow_vector());
      }
      return;
    }
    mapping_->insert_keyframe(std::move(keyframe));
    std::lock_guard lock(mutex_);
    max_queue_ = std::max(max_queue_, mapping_->queue_size());
  }
  bool accepts_keyframes() const override { return !mapping_ || mapping_->accepts_keyframes(); }
  size_t queued_keyframes() const override { return mapping_ ? mapping_->queue_size() : 0; }
  void interrupt_bundle_adjustment() override {
    if (mapping_) mapping_->interrupt_bundle_adjustment();
  }

  void wait_until_idle() {
    if (mapping_) mapping_->wait_until_idle();
  }
  LocalMapping* local_mapping() const { return mapping_.get(); }

  // Drains the queue (so the final map includes every keyframe), then joins the thread.
  void stop() {
    if (!mapping_) return;
    mapping_->wait_until_idle();
    poll();
    mapping_.reset();
  }

  void fill(MappingStats& stats) {
    poll();
    std::lock_guard lock(mutex_);
    stats.queued_keyframes = mapping_ ? mapping_->queue_size() : 0;
    stats.max_queued_keyframes = max_queue_;
    stats.processed_keyframes = processed_;
    stats.local_ba_ms_total = ba_ms_total_;
    stats.keyframes_culled = last_.keyframes_culled;
    stats.points_culled = last_.points_culled;
    stats.points_triangulated = last_.points_triangulated;
    stats.points_fused = last_.points_fused;
    stats.ba_outliers_removed = last_.ba_outliers_removed;
    stats.local_ba_cut_short = last_.bundle_adjustments_interrupted;
  }

 private:
  // LocalMapping reports the duration of the last BA; summed here once per new BA. Polled at
  // every frame, which is more often than keyframes (and so BAs) complete.
  void poll() {
    if (!mapping_) return;
    const LocalMappingStats stats = mapping_->stats();
    std::lock_guard lock(mutex_);
    if (stats.bundle_adjustments > bundle_adjustments_seen_) {
      ba_ms_total_ += 1000.0 * stats.last_bundle_adjustment_seconds *
                      static_cast<double>(stats.bundle_adjustments - bundle_adjustments_seen_);
      bundle_adjustments_seen_ = stats.bundle_adjustments;
    }
    processed_ = stats.keyframes_processed;
    last_ = stats;
  }

  std::unique_ptr<LocalMapping> mapping_;
  std::shared_ptr<PlaceRecognition> place_;  // indexes keyframes itself when mapping_ is null
  std::mutex mutex_;
  size_t max_queue_ = 0;
  size_t processed_ = 0;
  std::uint64_t bundle_adjustments_seen_ = 0;
  double ba_ms_total_ = 0.0;
  LocalMappingStats last_;
};

System::System(const SystemConfig& config, SystemOptions options)
    : camera_(std::make_shared<const CameraModel>(
          CameraModel::from_config(config.camera, options.virtual_baseline))),
      pyramid_(std::make_shared<const ScalePyramid>(ScalePyramid::from_config(config.orb))),
      frame_builder_(
          make_frame_builder(config, camera_, pyramid_, options.dynamic.mode != DynamicMode::off)),
      extractor_(std::make_unique<OrbExtractor>(config.orb)),
      map_(std::make_shared<Map>()) {
  // What this sensor cannot run (the runner applied it already to print why; again here for
  // callers that build a System directly).
  apply_sensor_limits(config.camera.type, options);
  if (options.localization_only) {
    // Nothing may change the map: no keyframes means nothing for these threads to do.
    options.local_mapping = false;
    options.place.loop_closing = false;
    options.tracker.localization_only = true;
  }
  if (options.place.needs_vocabulary()) {
    const std::filesystem::path vocabulary =
        options.place.vocabulary.empty() ? default_vocabulary_path() : options.place.vocabulary;
    place_ = PlaceRecognition::load(vocabulary);
  }
  std::unique_ptr<LocalMapping> mapping;
  if (options.local_mapping) {
    LocalMappingOptions mapping_options;
    mapping_options.close_depth = config.camera.depth_threshold;
    mapping_options.max_local_keyframes = options.local_ba_keyframes;
    // The BA's wall-clock budget keeps a live system responsive; a synchronous run bounds BA by
    // its iteration counts only, so its result does not depend on the machine's load.
    if (options.back_end_wait != BackEndWait::none)
      mapping_options.bundle_adjustment.max_seconds = std::numeric_limits<double>::infinity();
    if (config.camera.depth_noise == CameraConfig::DepthNoise::kinect_v1)
      mapping_options.bundle_adjustment.depth_noise = {.enabled = true,
                                                       .scale = config.camera.depth_noise_scale};
    mapping_options.thread_nice = options.background_thread_nice;
    frame_builder_->adapt(mapping_options);
    mapping = std::make_unique<LocalMapping>(map_, mapping_options, place_);
  }
  mapping_ = std::make_unique<MappingConnection>(std::move(mapping), place_);
  // ORB-SLAM2 wants a keyframe at least once per second of video.
  options.tracker.keyframes.max_frames_between = static_cast<int>(config.camera.fps);
  if (config.camera.depth_noise == CameraConfig::DepthNoise::kinect_v1)
    options.tracker.pose_optimizer.depth_noise = {.enabled = true,
                                                  .scale = config.camera.depth_noise_scale};
  tracker_ = std::make_unique<Tracker>(*map_, mapping_.get(), options.tracker,
                                       options.place.relocalization ? place_ : nullptr,
                                       frame_builder_->make_map_initializer(options.tracker));
  if (!options.map_file.empty()) {
    load_map(options.map_file, *map_, camera_, pyramid_);
    if (place_) {
      for (const auto& keyframe : map_->keyframes()) {
        keyframe->compute_bow(place_->vocabulary(), place_->direct_index_level());
        place_->database().add(keyframe->id(), keyframe->bow_vector());
      }
    }
    tracker_->start_in_loaded_map();
  }
  back_end_wait_ = options.back_end_wait;
  record_keypoint_fates_ = options.record_keypoint_fates;
  if (options.place.loop_closing && place_ && mapping_->local_mapping() != nullptr) {
    LoopClosingOptions loop_options;
    loop_options.thread_nice = options.background_thread_nice;
    frame_builder_->adapt(loop_options);
    // The global BA weighs depth as local BA does; otherwise it moves weakly connected keyframes
    // away from where local BA's depth constraint held them.
    if (config.camera.depth_noise == CameraConfig::DepthNoise::kinect_v1)
      loop_options.global_ba.depth_noise = {.enabled = true,
                                            .scale = config.camera.depth_noise_scale};
    // The callback runs on a loop closing thread with Map::update_mutex() held, so the tracker
    // (which holds it for a whole frame) is never re-anchored in the middle of a frame.
    loop_closing_ = std::make_unique<LoopClosing>(map_, place_, mapping_->local_mapping(),
                                                  loop_options, [this] {
                                                    tracker_->on_map_corrected();
                                                    ++map_corrections_;
                                                  });
    mapping_->local_mapping()->set_keyframe_listener(
        [loop = loop_closing_.get()](const std::shared_ptr<KeyFrame>& keyframe) {
          loop->insert_keyframe(keyframe);
        });
  }
  if (options.dynamic.mode != DynamicMode::off) {
    options.dynamic.semantic.thread_nice = options.background_thread_nice;
    options.dynamic.geometry = config.geometry;
    dynamic_ = std::make_unique<DynamicPipeline>(options.dynamic, config.camera.pinhole, *map_);
    if (options.localization_only) dynamic_->use_loaded_map_only();
  }
}

System::~System() { shutdown(); }

FrameReport System::track(const InputFrame& frame, const cv::Mat& dynamic_mask) {
  FrameReport report;
  const auto start = std::chrono::steady_clock::now();
  const double cpu_start = thread_cpu_ms();
  cv::Mat gray = frame.gray;
  if (gray.empty()) cv::cvtColor(frame.bgr, gray, cv::COLOR_BGR2GRAY);
  OrbFeatures features;
  frame_builder_->extract(frame, gray, dynamic_mask, features);
  Frame tracked_frame = frame_builder_->build(next_frame_id_++, frame, std::move(features), {},
                                              tracker_->angular_velocity());
  report.extraction_ms = milliseconds_since(start);
  const double cpu_tracking_start = thread_cpu_ms();
  report.extraction_cpu_ms = cpu_tracking_start - cpu_start;
  wait_for_back_end();
  const auto tracking_start = std::chrono::steady_clock::now();
  report.tracking = tracker_->track(std::move(tracked_frame));
  if (report.tracking.restart_due) restart_map();
  report.tracking_ms = milliseconds_since(tracking_start);
  report.tracking_cpu_ms = thread_cpu_ms() - cpu_tracking_start;
  return report;
}

FrameReport System::track(Timestamp timestamp, const cv::Mat& gray, const cv::Mat& depth_metres,
                          const cv::Mat& dynamic_mask) {
  InputFrame frame;
  frame.timestamp = timestamp;
  frame.gray = gray;
  frame.depth = depth_metres;
  return track(frame, dynamic_mask);
}

void System::announce(const InputFrame& frame) {
  frame_builder_->prepare(frame);
  if (dynamic_) dynamic_->announce(frame);
}

FrameReport System::process(const InputFrame& frame) {
  if (!dynamic_) {
    FrameReport report = track(frame);
    if (record_keypoint_fates_) record_fates_of_tracked_frame(report.keypoints);
    return report;
  }
  FrameReport report;
  const double cpu_start = thread_cpu_ms();
  cv::Mat gray = frame.gray;
  if (gray.empty()) cv::cvtColor(frame.bgr, gray, cv::COLOR_BGR2GRAY);
  const cv::Mat semantic_mask = dynamic_->begin_frame(frame, gray, report.dynamic);

  const auto extraction_start = std::chrono::steady_clock::now();
  OrbFeatures features;
  frame_builder_->extract(frame, gray, semantic_mask, features);
  const cv::Mat depth = frame_builder_->depth_image(frame);
  report.extraction_ms = milliseconds_since(extraction_start);
  {
    // A loop correction or global BA moved the map since the last frame: the geometry prior
    // must start from the tracker's corrected pose, not the one recorded before the move.
    std::lock_guard lock(map_->update_mutex());
    if (map_corrections_ != map_corrections_seen_) {
      map_corrections_seen_ = map_corrections_;
      dynamic_->reanchor_last_pose(tracker_->last_tracked_world_pose());
    }
  }
  std::vector<KeypointRecord>* fates = record_keypoint_fates_ ? &report.keypoints : nullptr;
  if (fates && record_masked_fates_) record_fates_before_removal(gray, semantic_mask, *fates);
  dynamic_->remove_dynamic(depth, frame_builder_->keypoint_depths(), semantic_mask, features,
                           report.dynamic, fates);
  const auto frame_start = std::chrono::steady_clock::now();
  Frame tracked_frame = frame_builder_->build(next_frame_id_++, frame, std::move(features), depth,
                                              tracker_->angular_velocity());
  report.extraction_ms += milliseconds_since(frame_start);
  report.extraction_cpu_ms = thread_cpu_ms() - cpu_start;  // includes flow and geometry

  wait_for_back_end();
  const double cpu_tracking_start = thread_cpu_ms();
  const auto tracking_start = std::chrono::steady_clock::now();
  report.tracking = tracker_->track(std::move(tracked_frame));
  if (report.tracking.restart_due) restart_map();
  report.tracking_ms = milliseconds_since(tracking_start);
  report.tracking_cpu_ms = thread_cpu_ms() - cpu_tracking_start;
  // The culler below and the next frame's geometry stage read map points and keyframe poses that
  // local mapping and loop closing refine: a deterministic run lets them finish this frame's
  // keyframe first, or the result would depend on thread timing and differ from run to run
  // (docs/decisions/back-end-wait.md).
  wait_for_back_end();
  dynamic_->end_frame(report.tracking, depth, semantic_mask, report.dynamic);
  if (fates) record_fates_of_tracked_frame(*fates);
  return report;
}

// The semantic mask is the extraction mask, so the features it removes never exist as keypoints.
// To show them, the frame is extracted once more without the mask (into a buffer of its own, so
// the tracked features are untouched) and the keypoints on the mask are recorded.
void System::record_fates_before_removal(const cv::Mat& gray, const cv::Mat& semantic_mask,
                                         std::vector<KeypointRecord>& records) {
  if (semantic_mask.empty()) return;
  extractor_->extract(gray, cv::Mat(), unmasked_features_);
  for (const cv::KeyPoint& keypoint : unmasked_features_.keypoints) {
    const int u = std::clamp(cvRound(keypoint.pt.x), 0, semantic_mask.cols - 1);
    const int v = std::clamp(cvRound(keypoint.pt.y), 0, semantic_mask.rows - 1);
    if (semantic_mask.at<std::uint8_t>(v, u) != 0)
      records.push_back({keypoint.pt, KeypointFate::semantic});
  }
}

// The keypoints that reached tracking: matched to a map point after pose optimisation or not
// (the tracker has already cleared the matches of pose outliers).
void System::record_fates_of_tracked_frame(std::vector<KeypointRecord>& records) const {
  const Frame* tracked = tracker_->last_frame();
  if (tracked == nullptr) return;
  const std::vector<cv::KeyPoint>& keypoints = tracked->keypoints();
  for (size_t i = 0; i < keypoints.size(); ++i) {
    records.push_back({keypoints[i].pt,
                       tracked->map_points[i] ? KeypointFate::tracked : KeypointFate::unmatched});
  }
}

void System::restart_map() {
  // Local mapping may still hold keyframes of the map about to go: let it finish them first.
  mapping_->wait_until_idle();
  std::lock_guard lock(map_->update_mutex());
  if (place_) {
    for (const auto& keyframe : map_->keyframes()) place_->database().erase(keyframe->id());
  }
  map_->clear();
  tracker_->restart();
}

void System::wait_for_back_end() {
  if (back_end_wait_ == BackEndWait::none) return;
  mapping_->wait_until_idle();
  if (back_end_wait_ == BackEndWait::whole_back_end && loop_closing_) {
    // Loop closing gets each keyframe after local mapping; a correction pauses local mapping
    // and the global BA runs after it, so mapping is waited for once more.
    loop_closing_->wait_until_idle();
    mapping_->wait_until_idle();
  }
}

cv::Mat System::last_dynamic_mask() const { return dynamic_ ? dynamic_->fused_mask() : cv::Mat(); }

const GeometryPicture* System::last_geometry_picture() const {
  return dynamic_ ? &dynamic_->geometry_picture() : nullptr;
}

cv::Mat System::last_semantic_labels() const {
  return dynamic_ ? dynamic_->semantic_labels() : cv::Mat();
}

void System::shutdown() {
  if (loop_closing_ && mapping_->local_mapping() != nullptr) {
    // Every keyframe reaches loop closing, its loops are closed and the global BA is applied
    // (offline runs want the final map); a correction may have paused local mapping meanwhile.
    mapping_->wait_until_idle();
    loop_closing_->wait_until_idle();
    mapping_->wait_until_idle();
    mapping_->local_mapping()->set_keyframe_listener({});
    // loop_closing_ stays (idle, its threads parked) so that mapping_stats() can report it.
  }
  mapping_->stop();
}

std::pair<size_t, size_t> System::save_map(const std::filesystem::path& file) {
  const MapFileSummary summary = pspslam::save_map(*map_, *camera_, *pyramid_, file);
  return {summary.keyframes, summary.map_points};
}

Trajectory System::keyframe_trajectory() const {
  Trajectory trajectory;
  for (const auto& keyframe : map_->keyframes()) {
    trajectory.push_back({keyframe->timestamp(), keyframe->T_world_camera()});
  }
  return trajectory;
}

MappingStats System::mapping_stats() const {
  MappingStats stats;
  stats.keyframes_in_map = map_->num_keyframes();
  stats.map_points = map_->num_map_points();
  mapping_->fill(stats);
  if (loop_closing_) {
    const LoopClosingStats loop = loop_closing_->stats();
    stats.loops_closed = loop.loops_closed;
    stats.loop_candidates_rejected = loop.detector.rejected_geometry;
    stats.global_ba_applied = loop.global_ba_applied;
    stats.global_ba_aborted = loop.global_ba_aborted;
    stats.last_loop_correction_m = loop.last_correction.correction_m;
    stats.last_loop_correction_scale = loop.last_correction.correction_scale;
    stats.last_global_ba_seconds = loop.last_global_ba_seconds;
  }
  return stats;
}

}  // namespace pspslam
