#include "pspslam/session/run_statistics.h"

#include <algorithm>
#include <nlohmann/json.hpp>

namespace pspslam {

TimingSummary summarize(std::vector<double> values) {
  TimingSummary summary;
  summary.count = values.size();
  if (values.empty()) return summary;
  std::sort(values.begin(), values.end());
  double sum = 0.0;
  for (const double v : values) sum += v;
  summary.mean = sum / static_cast<double>(values.size());
  summary.median = values[values.size() / 2];
  summary.p95 = values[std::min(values.size() - 1,
                                static_cast<size_t>(0.95 * static_cast<double>(values.size())))];
  return summary;
}

nlohmann::ordered_json to_json(const TimingSummary& timing) {
  return {{"median", timing.median},
          {"mean", timing.mean},
          {"p95", timing.p95},
          {"count", timing.count}};
}

LatencySummary summarize_latency(std::vector<double> values) {
  LatencySummary summary;
  summary.count = values.size();
  if (values.empty()) return summary;
  std::sort(values.begin(), values.end());
  summary.median = values[values.size() / 2];
  summary.p99 = values[std::min(values.size() - 1,
                                static_cast<size_t>(0.99 * static_cast<double>(values.size())))];
  summary.max = values.back();
  return summary;
}

nlohmann::ordered_json to_json(const LatencySummary& latency) {
  return {{"median", latency.median},
          {"p99", latency.p99},
          {"max", latency.max},
          {"count", latency.count}};
}

void RunStatistics::add_frame(size_t index, const FrameReport& report, LocalBaTime local_ba) {
  const TrackResult& result = report.tracking;
  count_pose(index, result);
  follow_lost_stretch(index, result);
  add_timings(report, local_ba);
  const DynamicReport& dyn = report.dynamic;
  add_live_masks(dyn);
  if (result.pose_held) ++frames_pose_held;
  if (result.unjudged_matches_set_aside > 0) ++poses_judged_first;
  unjudged_matches_set_aside += static_cast<size_t>(result.unjudged_matches_set_aside);
  tested_points += dyn.tested_points;
  dynamic_points += dyn.dynamic_points;
  masked_keypoints += dyn.masked_keypoints;
  culled_points += dyn.culled_map_points;
  ++processed_;
}

// Poses, relocalisations, the blackout's return and the (re)starts of the map.
void RunStatistics::count_pose(size_t index, const TrackResult& result) {
  if (result.method == TrackingMethod::kRelocalisation) ++relocalisations_;
  if (blackout_ && index >= blackout_->end() && !first_pose_after_blackout_ &&
      result.T_world_camera) {
    first_pose_after_blackout_ = index;
    first_method_after_blackout_ = to_string(result.method);
  }
  if (!result.T_world_camera) ++lost_;
  if (result.T_world_camera) ++posed_in_this_map_;
  if (result.restart_due) {
    // The frames tracked in the map that was restarted leave the trajectory (FrameLog).
    lost_ += posed_in_this_map_;
    posed_in_this_map_ = 0;
  }
  // Frames before the start that the new map placed had been counted as without a pose.
  const size_t placed = std::min(result.earlier_frames.size(), lost_);
  lost_ -= placed;
  posed_in_this_map_ += placed;
  if (result.T_world_camera) {
    MapFrames& map = frames_per_map_[result.map_id];
    if (map.frames == 0) map.first_frame = index - std::min(index, result.earlier_frames.size());
    map.frames += 1 + result.earlier_frames.size();
    map.last_frame = index;
  }
  if (result.method == TrackingMethod::kInitialization && !result.new_map) {
    placed_before_initialisation_ = placed;
    initialised_at_ = index;
    tracked_since_initialisation_ = 0;
    processed_since_initialisation_ = 0;
  }
  if (initialised_at_) {
    ++processed_since_initialisation_;
    if (result.T_world_camera) ++tracked_since_initialisation_;
  }
  if (result.restart_due) ++map_restarts_;
}

// The stretches of lost frames, and the longest of them.
void RunStatistics::follow_lost_stretch(size_t index, const TrackResult& result) {
  if (result.state == TrackingState::kLost && !result.T_world_camera) {
    if (!current_lost_) {
      current_lost_ = LostStretch{index, index, 0};
      ++lost_stretches_;
    }
    current_lost_->last_frame = index;
    ++current_lost_->frames;
    if (!longest_lost_ || current_lost_->frames > longest_lost_->frames ||
        current_lost_->first_frame == longest_lost_->first_frame) {
      longest_lost_ = current_lost_;
    }
  } else if (current_lost_) {
    // A frame with a pose ends the stretch, or the first frame of a new map (monocular restart).
    if (longest_lost_->first_frame == current_lost_->first_frame) {
      longest_lost_->end =
          result.T_world_camera ? LostStretch::End::tracked_again : LostStretch::End::map_restarted;
    }
    current_lost_.reset();
  }
}

// Per-module milliseconds and the ages of the masks.
void RunStatistics::add_timings(const FrameReport& report, LocalBaTime local_ba) {
  if (local_ba.wall_ms > 0.0) {
    local_mapping_ms.push_back(local_ba.wall_ms);
    local_mapping_cpu_ms.push_back(local_ba.cpu_ms);
    local_mapping_at.push_back(processed_);
  }
  extraction_ms.push_back(report.extraction_ms);
  tracking_ms.push_back(report.tracking_ms);
  tracking_cpu_ms.push_back(report.tracking_cpu_ms);
  const DynamicReport& dyn = report.dynamic;
  if (mode_ != DynamicMode::off) flow_ms.push_back(dyn.flow_ms);
  if (uses_semantics(mode_)) {
    semantic_wait_ms.push_back(dyn.semantic_wait_ms);
    if (dyn.mask_age_frames < 0) {
      ++frames_without_mask;
    } else {
      mask_age_frames.push_back(dyn.mask_age_frames);
      mask_latency_ms.push_back(dyn.mask_latency_ms);
      // Count each mask's inference once (a mask may serve several frames in real time).
      if (dyn.semantic_inference_ms != last_inference_ms_)
        semantic_ms.push_back(dyn.semantic_inference_ms);
      last_inference_ms_ = dyn.semantic_inference_ms;
    }
  }
  if (dyn.geometry_ran) {
    geometry_ms.push_back(dyn.geometry_ms);
    geometry_search_ms.push_back(dyn.geometry_search_ms);
  }
}

void RunStatistics::add_live_masks(const DynamicReport& dynamic) {
  if (dynamic.mask_age_frames > stale_mask_frames_) ++frames_on_stale_mask;
  if (dynamic.mask_moved_by_flow) ++frames_mask_moved_by_flow;
  if (dynamic.geometry_tightened) ++frames_geometry_tightened;
  if (dynamic.late_frame_judged) ++late_frames_judged;
  culled_by_late_masks += static_cast<size_t>(dynamic.culled_by_late_mask);
  const auto count = [](std::vector<size_t>& counts, int level) {
    if (level < 0) return;
    if (counts.size() <= static_cast<size_t>(level)) counts.resize(static_cast<size_t>(level) + 1);
    ++counts[static_cast<size_t>(level)];
  };
  count(frames_at_pace_level, dynamic.semantic_pace_level);
  count(masks_at_pace_level, dynamic.semantic_level);
  if (dynamic.semantic_pace_level >= 0) {
    if (last_pace_level_ >= 0 && dynamic.semantic_pace_level != last_pace_level_)
      ++pace_level_changes;
    last_pace_level_ = dynamic.semantic_pace_level;
  }
}

}  // namespace pspslam
