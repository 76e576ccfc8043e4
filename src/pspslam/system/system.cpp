// Thread layout of the SLAM system (PSPNet-SLAM, paper Fig. 1). System creates every thread
// object and wires them; the caller thread's work is TrackingModule::process (tracking_module.h),
// whose dynamic-scene steps 1, 2, 4 and 6 below are DynamicPipeline (dynamic/dynamic_pipeline.h),
// which owns the semantic thread. Frames come from the caller: `pspslam run` feeds a recorded
// sequence through SequenceRunner (session/).
//
//   semantic thread         SemanticThread (semantic/): one Segmenter (our PSPNet over ONNX);
//     (modes semantic,        frames are announce()d ahead of process(), so the network works on
//      full, exhaustive)      frame i+1 while the caller tracks frame i; publishes label maps and
//                             dilated dynamic-class masks by frame id
//                                  | newest / own-frame mask
//                                  v
//   caller thread           TrackingModule::process(), per frame, in this order (steps 1, 2, 4, 6:
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
//                             3D-3D RANSAC verification (a place in another map of the atlas
//                             merges the two first: loop/map_merge.h); for a loop: stops local
//                             mapping, correct_loop() under Map::update_mutex() (fusion, essential
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
#include <limits>
#include <mutex>
#include <optional>
#include <vector>

#include "pspslam/dynamic/dynamic_pipeline.h"
#include "pspslam/feature/orb_config.h"
#include "pspslam/geometry/geometry_config.h"
#include "pspslam/loop/loop_closing.h"
#include "pspslam/map/camera_model.h"
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
    stats.local_ba_cpu_ms_total = ba_cpu_ms_total_;
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
      const auto new_ones =
          static_cast<double>(stats.bundle_adjustments - bundle_adjustments_seen_);
      ba_ms_total_ += 1000.0 * stats.last_bundle_adjustment_seconds * new_ones;
      ba_cpu_ms_total_ += stats.last_bundle_adjustment_cpu_ms * new_ones;
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
  double ba_cpu_ms_total_ = 0.0;
  LocalMappingStats last_;
};

namespace {

LocalMappingOptions local_mapping_options(const SystemConfig& config, const SystemOptions& options,
                                          const FrameBuilder& frame_builder) {
  LocalMappingOptions mapping;
  mapping.close_depth = config.camera.depth_threshold;
  mapping.max_local_keyframes = options.local_ba_keyframes;
  mapping.max_fixed_keyframes = options.local_ba_fixed_keyframes;
  mapping.tracked_motion_weight = options.ba_tracking_factors;
  // The BA's wall-clock budget keeps a live system responsive; a synchronous run bounds BA by
  // its iteration counts only, so its result does not depend on the machine's load.
  if (options.back_end_wait != BackEndWait::none)
    mapping.bundle_adjustment.max_seconds = std::numeric_limits<double>::infinity();
  if (config.camera.depth_noise == CameraConfig::DepthNoise::kinect_v1)
    mapping.bundle_adjustment.depth_noise = {.enabled = true,
                                             .scale = config.camera.depth_noise_scale};
  mapping.thread_nice = options.background_thread_nice;
  frame_builder.adapt(mapping);
  return mapping;
}

LoopClosingOptions loop_closing_options(const SystemConfig& config, const SystemOptions& options,
                                        const FrameBuilder& frame_builder) {
  LoopClosingOptions loop;
  loop.thread_nice = options.background_thread_nice;
  frame_builder.adapt(loop);
  // The global BA weighs depth as local BA does; otherwise it moves weakly connected keyframes
  // away from where local BA's depth constraint held them.
  if (config.camera.depth_noise == CameraConfig::DepthNoise::kinect_v1)
    loop.global_ba.depth_noise = {.enabled = true, .scale = config.camera.depth_noise_scale};
  return loop;
}

// What a run asks for, less what its sensor and mode cannot do.
SystemOptions effective_options(const SystemConfig& config, SystemOptions options) {
  // What this sensor cannot run (the runner applied it already to print why; again here for
  // callers that build a System directly).
  apply_sensor_limits(config.camera.type, options);
  if (options.localization_only) {
    // Nothing may change the map: no keyframes means nothing for these threads to do.
    options.local_mapping = false;
    options.place.loop_closing = false;
    options.tracker.localization_only = true;
  }
  return options;
}

}  // namespace

void check_config_sections(const SystemConfig& config) {
  read_orb_config(config.orb);
  read_geometry_config(config.geometry);
}

System::System(const SystemConfig& config, SystemOptions requested)
    : camera_(std::make_shared<const CameraModel>(
          CameraModel::from_config(config.camera, requested.virtual_baseline))),
      pyramid_(std::make_shared<const ScalePyramid>(
          ScalePyramid::from_config(read_orb_config(config.orb)))),
      map_(std::make_shared<Map>()) {
  check_config_sections(config);
  const SystemOptions options = effective_options(config, std::move(requested));
  back_end_wait_ = options.back_end_wait;
  if (options.place.needs_vocabulary()) {
    place_ = PlaceRecognition::load(options.place.vocabulary.empty() ? default_vocabulary_path()
                                                                     : options.place.vocabulary);
  }
  std::unique_ptr<FrameBuilder> frame_builder =
      make_frame_builder(config, camera_, pyramid_, options.dynamic.mode != DynamicMode::off);
  const LoopClosingOptions loop_options = loop_closing_options(config, options, *frame_builder);
  std::unique_ptr<LocalMapping> mapping;
  if (options.local_mapping) {
    mapping = std::make_unique<LocalMapping>(
        map_, local_mapping_options(config, options, *frame_builder), place_);
  }
  mapping_ = std::make_unique<MappingConnection>(std::move(mapping), place_);
  tracking_ = std::make_unique<TrackingModule>(
      config, options, std::move(frame_builder), *map_, mapping_.get(), place_,
      BackEndHooks{.wait_for_back_end = [this] { wait_for_back_end(); },
                   .wait_for_local_mapping = [this] { mapping_->wait_until_idle(); }});
  if (!options.map_file.empty()) {
    load_map(options.map_file, *map_, camera_, pyramid_);
    map_->set_active_map(map_->map_ids().front());
    if (place_) {
      for (const auto& keyframe : map_->keyframes()) {
        keyframe->compute_bow(place_->vocabulary(), place_->direct_index_level());
        place_->database().add(keyframe->id(), keyframe->bow_vector());
      }
    }
    tracking_->start_in_loaded_map(options.localization_only);
  }
  if (options.place.loop_closing && place_ && mapping_->local_mapping() != nullptr) {
    // The callback runs on a loop closing thread with Map::update_mutex() held, so the tracker
    // (which holds it for a whole frame) is never re-anchored in the middle of a frame.
    loop_closing_ =
        std::make_unique<LoopClosing>(map_, place_, mapping_->local_mapping(), loop_options,
                                      [this] { tracking_->on_map_corrected(); });
    mapping_->local_mapping()->set_keyframe_listener(
        [loop = loop_closing_.get()](const std::shared_ptr<KeyFrame>& keyframe) {
          loop->insert_keyframe(keyframe);
        });
  }
}

System::~System() { shutdown(); }

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

Trajectory System::keyframe_trajectory(std::optional<std::uint32_t> map_id) const {
  Trajectory trajectory;
  for (const auto& keyframe : map_->keyframes()) {
    if (map_id && keyframe->map_id() != *map_id) continue;
    trajectory.push_back({keyframe->timestamp(), keyframe->T_world_camera()});
  }
  return trajectory;
}

MappingStats System::mapping_stats() const {
  MappingStats stats;
  stats.keyframes_in_map = map_->num_keyframes();
  stats.map_points = map_->num_map_points();
  stats.maps = map_->map_ids();
  stats.map_merges = map_->merges();
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
