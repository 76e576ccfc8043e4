#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <opencv2/core.hpp>
#include <utility>
#include <vector>

#include "pspslam/config/config.h"
#include "pspslam/core/types.h"
#include "pspslam/dynamic/dynamic_pipeline.h"
#include "pspslam/tracking/tracker.h"

namespace pspslam {

class DynamicPipeline;
class FrameBuilder;
class LocalMapping;
class LoopClosing;
class Map;
class OrbExtractor;
class PlaceRecognition;
struct InputFrame;
struct CameraModel;
struct ScalePyramid;

// Place recognition: bag-of-words vocabulary and keyframe database.
struct PlaceOptions {
  // Vocabulary file (`pspslam run --vocabulary`); empty = default_vocabulary_path()
  // (models/vocabulary/orb_k10_l5.pspvoc in the source tree).
  std::filesystem::path vocabulary;
  // Relocalise a lost tracker against the keyframe database. Needs the vocabulary, which is
  // then loaded at start-up and every keyframe gets a BoW vector in local mapping.
  bool relocalization = true;
  // Loop closing thread (`pspslam run --loop-closing`): detection, correction, global BA.
  // Needs the vocabulary and local mapping.
  bool loop_closing = true;

  // True when anything needs the vocabulary (relocalisation, loop closing).
  bool needs_vocabulary() const { return relocalization || loop_closing; }
};

enum class BackEndWait { none, local_mapping, whole_back_end };

struct SystemOptions {
  // ORB-SLAM2's virtual stereo baseline for RGB-D (u_r = u - fx * b / z), metres.
  double virtual_baseline = 0.08;
  TrackerOptions tracker;
  // false: keyframes go into the map but no local mapping runs (tests, debugging).
  bool local_mapping = true;
  // What each frame waits for before it is tracked (extraction still overlaps).
  // whole_back_end: local mapping has finished the keyframes before it, loop closing has looked
  // at them and any loop correction and global BA are applied. Offline accuracy runs want this:
  // otherwise the map a frame is tracked against, and whether a keyframe is accepted, depend on
  // how fast this machine is right now (a fast, unpaced run outruns local BA; frames tracked
  // between a loop correction and its global BA's write-back land centimetres off).
  // local_mapping: only local mapping (a camera fed at its own pace: a global BA takes seconds,
  // during which its driver would drop frames). none: a real-time feed never waits.
  BackEndWait back_end_wait = BackEndWait::none;
  // Local BA window size (LocalMappingOptions::max_local_keyframes; 0: every covisible one).
  int local_ba_keyframes = 0;
  // Nice increment of the semantic, local mapping and loop closing threads (and of the global
  // BA threads loop closing starts). A live run (--realtime, a camera) sets it so that the
  // caller thread, which must track each frame before the next one arrives, gets a core when
  // it needs one and the background work takes what is left (docs/decisions/realtime-nice.md).
  int background_thread_nice = 0;
  DynamicOptions dynamic;
  PlaceOptions place;
  // Map file to start from (`pspslam run --load-map`, persistence/map_file.h); empty: start a
  // new map. The first frame is relocalised in it (needs place.relocalization).
  std::filesystem::path map_file;
  // Localisation only (`--localization`): track against the map, never insert keyframes; no
  // local mapping and no loop closing run.
  bool localization_only = false;
  // Fill FrameReport::keypoints (pictures of a run, `pspslam run --save-overlays`). Off by
  // default: it costs a second, unmasked ORB extraction per frame with a semantic mask (the
  // keypoints the mask kept the extractor from returning) and a copy of every keypoint position.
  bool record_keypoint_fates = false;
};

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
};

struct MappingStats {
  size_t keyframes_in_map = 0;
  size_t map_points = 0;
  size_t queued_keyframes = 0;      // waiting for local mapping now
  size_t max_queued_keyframes = 0;  // over the run: growth means mapping cannot keep up
  size_t processed_keyframes = 0;
  double local_ba_ms_total = 0.0;  // wall time spent in local BA so far
  size_t keyframes_culled = 0;
  size_t points_culled = 0;
  size_t points_triangulated = 0;
  size_t points_fused = 0;
  size_t ba_outliers_removed = 0;
  size_t local_ba_cut_short = 0;  // stopped for a newer keyframe (or the time budget)
  // Loop closing (all zero when it is off).
  size_t loops_closed = 0;
  size_t loop_candidates_rejected = 0;  // consistent BoW candidates failing verification
  size_t global_ba_applied = 0;
  size_t global_ba_aborted = 0;
  double last_loop_correction_m = 0.0;      // how far the last loop moved its keyframe
  double last_loop_correction_scale = 1.0;  // and how it resized its neighbourhood (monocular)
  double last_global_ba_seconds = 0.0;
};

// The SLAM system: owns the map, the ORB extractor, the tracker (runs on the caller's thread
// inside track()) and the local mapping thread. The thread layout is in system.cpp.
class System {
 public:
  explicit System(const SystemConfig& config, SystemOptions options = {});
  ~System();
  System(const System&) = delete;
  System& operator=(const System&) = delete;

  // Tracks one frame. `dynamic_mask` (CV_8UC1, non-zero = do not extract features there) may
  // be empty. Uses frame.gray when present, else converts frame.bgr.
  FrameReport track(const InputFrame& frame, const cv::Mat& dynamic_mask = {});
  // RGB-D only (tests): the frame from its parts.
  FrameReport track(Timestamp timestamp, const cv::Mat& gray, const cv::Mat& depth_metres,
                    const cv::Mat& dynamic_mask = {});

  // The full PSPNet-SLAM path (options.dynamic): semantic mask + geometry verdicts -> dynamic
  // features removed -> tracking -> culling of map points on dynamic pixels. With mode `off` it
  // is track(frame). frame.bgr is required for the semantic modes.
  FrameReport process(const InputFrame& frame);
  // Hands a frame to the semantic thread ahead of process(frame), so that its segmentation
  // overlaps the tracking of the frame before (deterministic mode). Frames must be announced
  // in the order they are processed; a frame not announced is submitted by process().
  void announce(const InputFrame& frame);

  // Lets local mapping finish its queue and loop closing its loops and global bundle
  // adjustment, then stops their threads. Idempotent.
  void shutdown();

  // The fused dynamic mask (semantic + geometry, CV_8UC1, non-zero = dynamic) of the frame
  // process() handled last; empty with DynamicMode::off or before the first mask. Shared, not
  // copied: the next process() replaces it rather than writing into it.
  cv::Mat last_dynamic_mask() const;
  // Class labels (CV_8UC1) of the segmentation used for the frame process() handled last; empty
  // without semantics or a mask. Shared, not copied.
  cv::Mat last_semantic_labels() const;

  // The geometry stage's picture of the frame process() handled last (tested points, path,
  // grown regions); empty unless keypoint fates were recorded for that frame; null with
  // DynamicMode::off.
  const GeometryPicture* last_geometry_picture() const;
  // Turns SystemOptions::record_keypoint_fates on or off from the next frame on: the live viewer
  // pays for them only on the frames it shows. `masked` = also the keypoints the semantic mask
  // kept from being extracted, which costs a second, unmasked extraction (a real-time viewer
  // leaves them out and shows the mask instead).
  void set_record_keypoint_fates(bool record, bool masked = true) {
    record_keypoint_fates_ = record;
    record_masked_fates_ = masked;
  }

  // Writes the map (persistence/map_file.h); call after shutdown(). Throws pspslam::Error.
  // Returns the number of keyframes and map points written.
  std::pair<size_t, size_t> save_map(const std::filesystem::path& file);

  // Keyframe poses (T_world_camera), by keyframe id.
  Trajectory keyframe_trajectory() const;
  // All tracked frames, re-expressed through their BA-refined reference keyframes (see
  // Tracker::refined_trajectory); call after shutdown().
  Trajectory refined_trajectory() const { return tracker_->refined_trajectory(); }
  MappingStats mapping_stats() const;
  const Map& map() const { return *map_; }
  // Vocabulary + keyframe database; null when PlaceOptions needs no vocabulary.
  const std::shared_ptr<PlaceRecognition>& place_recognition() const { return place_; }

 private:
  class MappingConnection;

  // SystemOptions::back_end_wait.
  void wait_for_back_end();
  // TrackResult::restart_due: local mapping finishes, the map and the keyframe database are
  // emptied and the tracker starts a new map with the next frames.
  void restart_map();
  void record_fates_before_removal(const cv::Mat& gray, const cv::Mat& semantic_mask,
                                   std::vector<KeypointRecord>& records);
  void record_fates_of_tracked_frame(std::vector<KeypointRecord>& records) const;

  std::shared_ptr<const CameraModel> camera_;
  std::shared_ptr<const ScalePyramid> pyramid_;
  // Per-sensor: extraction, depth and the Frame (system/frame_builder.h).
  std::unique_ptr<FrameBuilder> frame_builder_;
  std::unique_ptr<OrbExtractor> extractor_;  // record_keypoint_fates' unmasked extraction only
  // Shared with the local mapping thread, which needs the map for as long as it runs.
  std::shared_ptr<Map> map_;
  // Shared with local mapping (indexes keyframes) and tracking (relocalisation queries).
  std::shared_ptr<PlaceRecognition> place_;
  // Declared before tracker_ so it is destroyed after it (the tracker points to it).
  std::unique_ptr<MappingConnection> mapping_;
  std::unique_ptr<Tracker> tracker_;
  // After mapping_ and tracker_: it stops local mapping and re-anchors the tracker, so it is
  // destroyed (threads joined) before them. Null when loop closing is off.
  std::unique_ptr<LoopClosing> loop_closing_;
  // Loop corrections / global BAs applied so far (written under Map::update_mutex()); the
  // dynamic pipeline re-reads the tracker's pose when it changed.
  std::uint64_t map_corrections_ = 0;
  std::uint64_t map_corrections_seen_ = 0;
  std::uint64_t next_frame_id_ = 0;
  BackEndWait back_end_wait_ = BackEndWait::none;
  bool record_keypoint_fates_ = false;
  bool record_masked_fates_ = true;  // with record_keypoint_fates_: the second extraction too
  OrbFeatures unmasked_features_;    // record_keypoint_fates only: reused every frame
  // Semantic thread, geometry stage and their per-frame state; null with DynamicMode::off.
  // Declared last: its threads stop before the tracker and map go away.
  std::unique_ptr<DynamicPipeline> dynamic_;
};

}  // namespace pspslam
