#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <utility>
#include <vector>

#include "pspslam/config/config.h"
#include "pspslam/core/types.h"
#include "pspslam/map/map.h"
#include "pspslam/system/system_options.h"
#include "pspslam/system/tracking_module.h"

namespace pspslam {

class LoopClosing;
class PlaceRecognition;
struct CameraModel;
struct ScalePyramid;

struct MappingStats {
  size_t keyframes_in_map = 0;
  size_t map_points = 0;
  size_t queued_keyframes = 0;      // waiting for local mapping now
  size_t max_queued_keyframes = 0;  // over the run: growth means mapping cannot keep up
  size_t processed_keyframes = 0;
  double local_ba_ms_total = 0.0;      // wall time spent in local BA so far
  double local_ba_cpu_ms_total = 0.0;  // its CPU time: the cost, whatever the machine's load
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
  // The atlas: the maps that hold keyframes now, and the merges so far (Map::merges).
  std::vector<std::uint32_t> maps;
  std::vector<MapMerge> map_merges;
};

// Reads every module's section of `config` as a System does: a bad key or value is an error
// naming the file, the line and the key, raised before a run opens its input or starts a thread.
void check_config_sections(const SystemConfig& config);

// The SLAM system: creates the map and the threads, wires them together and stops them. Each
// thread's loop is its own module: tracking (the caller's thread, system/tracking_module.h),
// local mapping (mapping/), loop closing (loop/); the semantic thread belongs to the tracking
// module's dynamic pipeline. The thread layout is in system.cpp.
class System {
 public:
  explicit System(const SystemConfig& config, SystemOptions options = {});
  ~System();
  System(const System&) = delete;
  System& operator=(const System&) = delete;

  // The full PSPNet-SLAM path for one frame (TrackingModule::process): semantic mask + geometry
  // verdicts -> dynamic features removed -> tracking -> culling of map points on dynamic
  // pixels; with DynamicMode::off, ORB-SLAM2's. Uses frame.gray when present, else converts
  // frame.bgr, which the semantic modes require.
  FrameReport process(const InputFrame& frame) { return tracking_->process(frame); }
  // Hands a frame to the semantic thread ahead of process(frame), so that its segmentation
  // overlaps the tracking of the frame before (deterministic mode). Frames must be announced
  // in the order they are processed; a frame not announced is submitted by process().
  void announce(const InputFrame& frame) { tracking_->announce(frame); }

  // Lets local mapping finish its queue and loop closing its loops and global bundle
  // adjustment, then stops their threads. Idempotent.
  void shutdown();

  // The fused dynamic mask (semantic + geometry, CV_8UC1, non-zero = dynamic) of the frame
  // process() handled last; empty with DynamicMode::off or before the first mask. Shared, not
  // copied: the next process() replaces it rather than writing into it.
  cv::Mat last_dynamic_mask() const { return tracking_->last_dynamic_mask(); }
  // Class labels (CV_8UC1) of the segmentation used for the frame process() handled last; empty
  // without semantics or a mask. Shared, not copied.
  cv::Mat last_semantic_labels() const { return tracking_->last_semantic_labels(); }
  // Whether frames report their people (FrameReport::people): a person class and depth exist.
  bool tracks_people() const { return tracking_->tracks_people(); }
  // The geometry stage's picture of the frame process() handled last (tested points, path,
  // grown regions); empty unless keypoint fates were recorded for that frame; null with
  // DynamicMode::off.
  const GeometryPicture* last_geometry_picture() const {
    return tracking_->last_geometry_picture();
  }
  // Turns SystemOptions::record_keypoint_fates on or off from the next frame on: the live viewer
  // pays for them only on the frames it shows. `masked` = also the keypoints the semantic mask
  // kept from being extracted, which costs a second, unmasked extraction (a real-time viewer
  // leaves them out and shows the mask instead).
  void set_record_keypoint_fates(bool record, bool masked = true) {
    tracking_->set_record_keypoint_fates(record, masked);
  }

  // Writes the map (persistence/map_file.h); call after shutdown(). Throws pspslam::Error.
  // Returns the number of keyframes and map points written.
  std::pair<size_t, size_t> save_map(const std::filesystem::path& file);

  // Keyframe poses (T_world_camera), by keyframe id; only those of one map of the atlas when
  // `map_id` is given.
  Trajectory keyframe_trajectory(std::optional<std::uint32_t> map_id = std::nullopt) const;
  // All tracked frames, re-expressed through their BA-refined reference keyframes (see
  // Tracker::refined_trajectory); call after shutdown().
  Trajectory refined_trajectory() const { return tracking_->tracker().refined_trajectory(); }
  // Per pose of refined_trajectory(), the map of the atlas it is in at the end.
  std::vector<std::uint32_t> refined_map_ids() const {
    return tracking_->tracker().refined_map_ids();
  }
  MappingStats mapping_stats() const;
  const Map& map() const { return *map_; }
  // Vocabulary + keyframe database; null when PlaceOptions needs no vocabulary.
  const std::shared_ptr<PlaceRecognition>& place_recognition() const { return place_; }

 private:
  class MappingConnection;

  // SystemOptions::back_end_wait.
  void wait_for_back_end();

  std::shared_ptr<const CameraModel> camera_;
  std::shared_ptr<const ScalePyramid> pyramid_;
  // Shared with the local mapping thread, which needs the map for as long as it runs.
  std::shared_ptr<Map> map_;
  // Shared with local mapping (indexes keyframes) and tracking (relocalisation queries).
  std::shared_ptr<PlaceRecognition> place_;
  // Declared before tracking_ so it is destroyed after it (the tracker points to it).
  std::unique_ptr<MappingConnection> mapping_;
  std::unique_ptr<TrackingModule> tracking_;
  // After mapping_ and tracking_: it stops local mapping and re-anchors the tracker, so it is
  // destroyed (threads joined) before them. Null when loop closing is off.
  std::unique_ptr<LoopClosing> loop_closing_;
  BackEndWait back_end_wait_ = BackEndWait::none;
};

}  // namespace pspslam
