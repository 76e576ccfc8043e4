#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "pspslam/config/config.h"
#include "pspslam/dynamic/dynamic_pipeline.h"
#include "pspslam/feature/orb_extractor.h"
#include "pspslam/io/input_frame.h"
#include "pspslam/people/people_tracking.h"
#include "pspslam/system/system_options.h"
#include "pspslam/tracking/tracker.h"

namespace pspslam {

class FrameBuilder;
class KeyFrameSink;
class Map;
class PlaceRecognition;

// One frame through the system: the tracking result and where the time went.
struct FrameReport {
  TrackResult tracking;
  double extraction_ms = 0.0;
  double tracking_ms = 0.0;
  // CPU time of the calling thread: on a shared, loaded machine wall time includes waiting
  // for a core, CPU time does not.
  double extraction_cpu_ms = 0.0;
  double tracking_cpu_ms = 0.0;
  DynamicReport dynamic;
  // Every keypoint of the frame and what became of it; empty unless
  // SystemOptions::record_keypoint_fates.
  std::vector<KeypointRecord> keypoints;
  // The people tracked in this frame (empty without depth or a person class: monocular, masks
  // read from files, --dynamic off or geometry).
  PeopleFrame people;
};

// What the tracking module needs from the threads behind it; System provides both. The defaults
// wait for nothing: without local mapping there is nothing to wait for.
struct BackEndHooks {
  // Blocks until the back end has caught up as SystemOptions::back_end_wait asks (does nothing
  // for BackEndWait::none).
  std::function<void()> wait_for_back_end = [] {};
  // Blocks until local mapping has finished every keyframe it holds.
  std::function<void()> wait_for_local_mapping = [] {};
};

// The caller thread's work: one frame from its images to its pose, the path of the paper's
// Fig. 1 (process()), and the state it keeps between frames: the per-sensor frame builder, the
// tracker, and the dynamic pipeline with its semantic thread. The thread layout around it is in
// system/system.cpp.
class TrackingModule {
 public:
  // `map` must outlive the module; `keyframe_sink` receives new keyframes (local mapping);
  // `place` (may be null) relocalises a lost tracker and is emptied with the map on a restart.
  TrackingModule(const SystemConfig& config, const SystemOptions& options,
                 std::unique_ptr<FrameBuilder> frame_builder, Map& map, KeyFrameSink* keyframe_sink,
                 std::shared_ptr<PlaceRecognition> place, BackEndHooks back_end);
  ~TrackingModule();
  TrackingModule(const TrackingModule&) = delete;
  TrackingModule& operator=(const TrackingModule&) = delete;

  // The whole per-frame path (see system.cpp for why each step sits where it does).
  FrameReport process(const InputFrame& frame);
  // Hands a frame to the semantic thread and the frame builder ahead of process(frame).
  void announce(const InputFrame& frame);

  // The map was loaded before the first frame: track against it (and, in localisation, keep
  // the dynamic pipeline from changing it).
  void start_in_loaded_map(bool localization_only);
  // A loop correction or global BA moved the map; called with Map::update_mutex() held.
  void on_map_corrected();

  void set_record_keypoint_fates(bool record, bool masked) {
    record_keypoint_fates_ = record;
    record_masked_fates_ = masked;
  }

  cv::Mat last_dynamic_mask() const { return dynamic_ ? dynamic_->fused_mask() : cv::Mat(); }
  cv::Mat last_semantic_labels() const {
    return dynamic_ ? dynamic_->semantic_labels() : cv::Mat();
  }
  const GeometryPicture* last_geometry_picture() const {
    return dynamic_ ? &dynamic_->geometry_picture() : nullptr;
  }
  const Tracker& tracker() const { return tracker_; }
  bool tracks_people() const { return people_ != nullptr; }

 private:
  // TrackResult::restart_due: local mapping finishes, the map and the keyframe database are
  // emptied and the tracker starts a new map with the next frames.
  void restart_map();
  // After a loop correction, the geometry prior starts from the tracker's corrected pose.
  void reanchor_dynamic_pipeline();
  std::optional<std::uint64_t> judged_through_frame(std::uint64_t frame_id,
                                                    const FrameReport& report) const;
  void record_fates_before_removal(const cv::Mat& gray, const cv::Mat& semantic_mask,
                                   std::vector<KeypointRecord>& records);
  void record_fates_of_tracked_frame(std::vector<KeypointRecord>& records) const;

  Map& map_;
  std::shared_ptr<PlaceRecognition> place_;
  BackEndHooks back_end_;
  // Per-sensor: extraction, depth and the Frame (system/frame_builder.h).
  std::unique_ptr<FrameBuilder> frame_builder_;
  Tracker tracker_;
  std::unique_ptr<OrbExtractor> extractor_;  // record_keypoint_fates' unmasked extraction only
  OrbFeatures unmasked_features_;            // reused every frame
  bool record_keypoint_fates_ = false;
  bool record_masked_fates_ = true;  // with record_keypoint_fates_: the second extraction too
  std::uint64_t next_frame_id_ = 0;
  // Loop corrections / global BAs applied so far (written under Map::update_mutex()); the
  // dynamic pipeline re-reads the tracker's pose when it changed.
  std::uint64_t map_corrections_ = 0;
  std::uint64_t map_corrections_seen_ = 0;
  // Semantic thread, geometry stage and their per-frame state; null with DynamicMode::off.
  // Declared last: its threads stop before the tracker goes away.
  std::unique_ptr<DynamicPipeline> dynamic_;
  // After the dynamic pipeline: it reads that pipeline's labels. Null where no person mask or
  // depth exists.
  std::unique_ptr<PeopleTracking> people_;
};

}  // namespace pspslam
