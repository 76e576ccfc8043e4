#pragma once

#include <cstddef>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <vector>

#include "pspslam/dynamic/dynamic_mode.h"
#include "pspslam/session/atlas_report.h"
#include "pspslam/session/run_options.h"
#include "pspslam/system/system.h"

namespace pspslam {

// {median, mean, p95} of one module's per-frame milliseconds.
struct TimingSummary {
  double median = 0.0;
  double mean = 0.0;
  double p95 = 0.0;
  size_t count = 0;
};

TimingSummary summarize(std::vector<double> values);
nlohmann::ordered_json to_json(const TimingSummary& timing);

// The real-time figures: median, p99 and max of a per-frame series (nearest-rank on
// the sorted values, the same rule as TimingSummary's p95).
struct LatencySummary {
  double median = 0.0;
  double p99 = 0.0;
  double max = 0.0;
  size_t count = 0;
};
LatencySummary summarize_latency(std::vector<double> values);
nlohmann::ordered_json to_json(const LatencySummary& latency);

// Local BA finished since the frame before: wall and CPU milliseconds (0: none).
struct LocalBaTime {
  double wall_ms = 0.0;
  double cpu_ms = 0.0;
};

// Accumulates what each frame of a run reports: per-module times, dynamic-feature totals, lost
// frames, relocalisations and (with a blackout) when poses came back. Read by run_report.h.
class RunStatistics {
 public:
  // `stale_mask_frames`: a mask older than this many frames counts as stale.
  RunStatistics(DynamicMode mode, std::optional<FrameRange> blackout, int stale_mask_frames = 2)
      : mode_(mode), blackout_(blackout), stale_mask_frames_(stale_mask_frames) {}

  // Frame `index` of the sequence, with the local BA time finished since the frame before.
  void add_frame(size_t index, const FrameReport& report, LocalBaTime local_ba = {});
  // Frames the real-time feed skipped since the last frame.
  void add_dropped(size_t frames) { realtime_dropped_ += frames; }

  size_t processed() const { return processed_; }
  size_t lost() const { return lost_; }
  size_t relocalisations() const { return relocalisations_; }
  size_t realtime_dropped() const { return realtime_dropped_; }
  std::optional<size_t> first_pose_after_blackout() const { return first_pose_after_blackout_; }
  const std::string& first_method_after_blackout() const { return first_method_after_blackout_; }
  // Sequence index of the frame that started the first map (the last start after a monocular
  // restart; new maps of the atlas do not count) and the frames with a pose from there on, of
  // the frames processed from there on.
  std::optional<size_t> initialised_at() const { return initialised_at_; }
  size_t tracked_since_initialisation() const { return tracked_since_initialisation_; }
  // Frames before the map's start that it placed (TrackResult::earlier_frames; monocular).
  size_t placed_before_initialisation() const { return placed_before_initialisation_; }
  size_t processed_since_initialisation() const { return processed_since_initialisation_; }
  size_t map_restarts() const { return map_restarts_; }
  // Consecutive frames lost after the map existed (frames before it started do not count):
  // how many such stretches, and the longest (the first of equal length) with how it ended.
  struct LostStretch {
    enum class End { still_lost, tracked_again, map_restarted };
    size_t first_frame = 0;
    size_t last_frame = 0;
    size_t frames = 0;
    End end = End::still_lost;  // still_lost: it reaches the last frame processed
  };
  size_t lost_stretches() const { return lost_stretches_; }
  std::optional<LostStretch> longest_lost_stretch() const { return longest_lost_; }

  std::vector<double> extraction_ms;
  std::vector<double> tracking_ms;
  std::vector<double> tracking_cpu_ms;
  std::vector<double> semantic_ms;  // inference time of each mask used (once per mask)
  std::vector<double> semantic_wait_ms;
  std::vector<double> geometry_ms;
  std::vector<double> geometry_search_ms;
  std::vector<double> flow_ms;
  std::vector<double> local_mapping_ms;      // one entry per local BA
  std::vector<double> local_mapping_cpu_ms;  // its CPU time
  std::vector<size_t> local_mapping_at;      // per local BA: frames processed before it ended
  std::vector<double> mask_age_frames;
  std::vector<double> mask_latency_ms;
  // Thread CPU of the run loop in a RunObserver's hooks per frame (`run --viewer`; a held loop
  // sleeps, which costs no CPU): what watching costs the frames, apart from the detail recorded
  // inside System::process for the shown frames.
  std::vector<double> observer_cpu_ms;
  // Frames with an arrival time (InputFrame::arrival: --realtime, cameras): from arrival to the
  // end of System::process(), i.e. until the pose (or the verdict that there is none) exists.
  std::vector<double> arrival_to_pose_ms;
  size_t tested_points = 0;
  size_t dynamic_points = 0;
  size_t masked_keypoints = 0;
  size_t culled_points = 0;
  size_t frames_without_mask = 0;
  // Live runs: frames whose mask was older than stale_mask_frames, whose mask moved by the
  // people's own flow, and whose geometry stage tested every keypoint near a stale mask.
  size_t frames_on_stale_mask = 0;
  size_t frames_mask_moved_by_flow = 0;
  size_t frames_geometry_tightened = 0;
  size_t frames_pose_held = 0;  // poses held at the motion model's prediction (MoverGuard)
  // Poses solved on judged map points first that set newer matches aside, and those matches.
  size_t poses_judged_first = 0;
  size_t unjudged_matches_set_aside = 0;
  // Earlier frames judged by their own late mask, and the map points that culled.
  size_t late_frames_judged = 0;
  size_t culled_by_late_masks = 0;
  // With a semantic pace: frames processed while the thread was at each level, and frames whose
  // mask was made at each level (index = level); how often the thread changed level.
  std::vector<size_t> frames_at_pace_level;
  std::vector<size_t> masks_at_pace_level;
  size_t pace_level_changes = 0;
  int stale_mask_frames() const { return stale_mask_frames_; }
  // The atlas: the frames each map held when they were tracked.
  const std::map<std::uint32_t, MapFrames>& frames_per_map() const { return frames_per_map_; }

 private:
  void count_pose(size_t index, const TrackResult& result);
  void follow_lost_stretch(size_t index, const TrackResult& result);
  void add_timings(const FrameReport& report, LocalBaTime local_ba);
  void add_live_masks(const DynamicReport& dynamic);

  DynamicMode mode_;
  std::optional<FrameRange> blackout_;
  int stale_mask_frames_ = 2;
  int last_pace_level_ = -1;
  size_t processed_ = 0;
  size_t lost_ = 0;
  size_t relocalisations_ = 0;
  size_t realtime_dropped_ = 0;
  double last_inference_ms_ = -1.0;
  std::optional<size_t> first_pose_after_blackout_;
  std::string first_method_after_blackout_;
  std::optional<size_t> initialised_at_;
  size_t tracked_since_initialisation_ = 0;
  size_t placed_before_initialisation_ = 0;
  size_t processed_since_initialisation_ = 0;
  size_t map_restarts_ = 0;
  size_t lost_stretches_ = 0;
  std::optional<LostStretch> current_lost_;
  std::optional<LostStretch> longest_lost_;
  size_t posed_in_this_map_ = 0;
  std::map<std::uint32_t, MapFrames> frames_per_map_;
};

}  // namespace pspslam
