#include "pspslam/session/run_report.h"

#include <spdlog/fmt/fmt.h>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <opencv2/core/utility.hpp>
#include <optional>
#include <tuple>
#include <utility>
#include <vector>

#include "pspslam/core/error.h"
#include "pspslam/core/median.h"
#include "pspslam/core/thread_priority.h"
#include "pspslam/core/version.h"
#include "pspslam/eval/ate.h"
#include "pspslam/eval/stats.h"
#include "pspslam/semantic/segmenter_metadata.h"
#include "pspslam/semantic/semantic_pace.h"
#include "pspslam/session/frame_log.h"

namespace pspslam {
namespace {

double median(std::vector<double> values) { return upper_median(values); }

void print_loop_stats(const MappingStats& mapping, bool monocular, std::ostream& out) {
  // A monocular map has no metric unit: the correction is in the map's units, and the loop
  // also resizes the neighbourhood of its keyframe (Sim(3)).
  char last[128] = "";
  if (mapping.loops_closed > 0 && monocular) {
    std::snprintf(last, sizeof(last), " (last moved its keyframe %.3f map units, resized it x%.3f)",
                  mapping.last_loop_correction_m, mapping.last_loop_correction_scale);
  } else if (mapping.loops_closed > 0) {
    std::snprintf(last, sizeof(last), " (last moved its keyframe %.3f m)",
                  mapping.last_loop_correction_m);
  }
  char line[512];
  std::snprintf(line, sizeof(line),
                "loops:        %zu closed%s, %zu candidates rejected by geometry; global BA %zu "
                "applied, %zu aborted (last %.2f s)\n",
                mapping.loops_closed, last, mapping.loop_candidates_rejected,
                mapping.global_ba_applied, mapping.global_ba_aborted,
                mapping.last_global_ba_seconds);
  out << line;
}

// "pspnet.yaml (384x288)" for a segmentation model; the file name alone when it does not load.
std::string describe_model(const std::filesystem::path& model) {
  try {
    const SegmenterMetadata meta = load_segmenter_metadata(model);
    return model.filename().string() + " (" + std::to_string(meta.input_width) + "x" +
           std::to_string(meta.input_height) + ")";
  } catch (const Error&) {
    return model.filename().string();
  }
}

// A live run's masks: how many frames ran on a stale mask, how masks were moved, and what the
// semantic thread stepped down to. Printed, and a stats.json member (null for other runs).
nlohmann::ordered_json report_live_masks(const RunReportInput& input, std::ostream& out) {
  const DynamicOptions& dynamic = input.options.system.dynamic;
  const RunStatistics& stats = input.statistics;
  if (!dynamic.realtime || !uses_semantics(dynamic.mode) || !dynamic.semantic_masks.empty())
    return nullptr;
  char line[768];
  std::snprintf(line, sizeof(line),
                "live masks:   %zu frames on a mask older than %d frames; stale masks moved by "
                "%s (%zu frames by the people's flow), %zu frames with the geometry test "
                "tightened around them, %zu poses held at the motion model\n"
                "              culling by exact masks only: %s (%zu frames judged by their own "
                "late mask, %zu map points culled so); judged points first: %s (%zu poses set "
                "%zu newer matches aside)\n",
                stats.frames_on_stale_mask, stats.stale_mask_frames(),
                dynamic.stale_masks == StaleMaskPolicy::flow ? "flow" : "homography",
                stats.frames_mask_moved_by_flow, stats.frames_geometry_tightened,
                stats.frames_pose_held, dynamic.cull_with_late_masks ? "on" : "off",
                stats.late_frames_judged, stats.culled_by_late_masks,
                input.options.system.tracker.judged_points_first ? "on" : "off",
                stats.poses_judged_first, stats.unjudged_matches_set_aside);
  out << line;
  nlohmann::ordered_json json = {
      {"stale_after_frames", stats.stale_mask_frames()},
      {"frames_on_stale_mask", stats.frames_on_stale_mask},
      {"stale_masks", dynamic.stale_masks == StaleMaskPolicy::flow ? "flow" : "homography"},
      {"frames_mask_moved_by_flow", stats.frames_mask_moved_by_flow},
      {"frames_geometry_tightened", stats.frames_geometry_tightened},
      {"frames_pose_held", stats.frames_pose_held},
      {"cull_with_late_masks", dynamic.cull_with_late_masks},
      {"late_frames_judged", stats.late_frames_judged},
      {"culled_by_late_masks", stats.culled_by_late_masks},
      {"judged_points_first", input.options.system.tracker.judged_points_first},
      {"poses_judged_first", stats.poses_judged_first},
      {"unjudged_matches_set_aside", stats.unjudged_matches_set_aside},
      {"pace", nullptr}};
  if (!dynamic.keep_pace) return json;
  const std::vector<std::filesystem::path> networks =
      dynamic.smaller_model.empty()
          ? std::vector<std::filesystem::path>{dynamic.model}
          : std::vector<std::filesystem::path>{dynamic.model, dynamic.smaller_model};
  const std::vector<PaceLevel> ladder =
      pace_ladder(static_cast<int>(networks.size()), std::max(1, dynamic.pace_max_stride));
  nlohmann::ordered_json levels = nlohmann::ordered_json::array();
  std::string text;
  for (size_t i = 0; i < ladder.size(); ++i) {
    const auto at = [&](const std::vector<size_t>& counts) {
      return i < counts.size() ? counts[i] : size_t{0};
    };
    const std::string network = describe_model(networks[static_cast<size_t>(ladder[i].network)]);
    levels.push_back({{"level", i},
                      {"network", network},
                      {"stride", ladder[i].stride},
                      {"frames", at(stats.frames_at_pace_level)},
                      {"frames_masked_at_level", at(stats.masks_at_pace_level)}});
    text += (i ? ", " : "") + std::to_string(i) + " " + network + " every " +
            (ladder[i].stride == 1 ? std::string("frame")
                                   : std::to_string(ladder[i].stride) + " frames") +
            ": " + std::to_string(at(stats.frames_at_pace_level));
  }
  const size_t stepped_down =
      stats.processed() -
      (stats.frames_at_pace_level.empty() ? stats.processed() : stats.frames_at_pace_level[0]);
  out << "semantic pace: frames at each level: " << text << "; " << stats.pace_level_changes
      << " level changes" << (stepped_down > 0 ? "" : " (never stepped down)") << "\n";
  json["pace"] = {{"levels", levels},
                  {"level_changes", stats.pace_level_changes},
                  {"frames_stepped_down", stepped_down}};
  return json;
}

// Blackout: how soon a pose came back, and how good the poses after the return are (errors of
// the whole run's alignment, restricted to frames from the return on). A stats.json member.
nlohmann::ordered_json report_blackout(const RunReportInput& input, const FrameRange& blackout,
                                       const std::optional<AteResult>& ate_tracked,
                                       std::ostream& out) {
  const RunStatistics& stats = input.statistics;
  char line[512];
  std::snprintf(line, sizeof(line), "blackout:     frames %zu-%zu black, %zu relocalisations; ",
                blackout.first, blackout.end() - 1, stats.relocalisations());
  out << line;
  const std::optional<size_t> first_pose = stats.first_pose_after_blackout();
  if (first_pose) {
    std::snprintf(line, sizeof(line), "first pose after the return at frame %zu (+%zu) by %s\n",
                  *first_pose, *first_pose - blackout.end(),
                  stats.first_method_after_blackout().c_str());
    out << line;
  } else {
    out << "no pose after the return\n";
  }
  std::optional<ErrorStats> after_return;
  if (ate_tracked && input.blackout_return) {
    const Timestamp returned = *input.blackout_return;
    std::vector<double> errors;
    for (const AtePair& pair : ate_tracked->pairs) {
      if (pair.est_timestamp >= returned) errors.push_back(pair.error);
    }
    if (!errors.empty()) {
      after_return = compute_error_stats(errors);
      std::snprintf(line, sizeof(line),
                    "              after the return: %zu poses, error RMSE %.4f m, max %.4f m\n",
                    after_return->count, after_return->rmse, after_return->max);
      out << line;
    }
  }
  return {
      {"first", blackout.first},
      {"count", blackout.count},
      {"frames_to_first_pose", first_pose ? static_cast<long>(*first_pose - blackout.end()) : -1L},
      {"after_return_rmse_m", after_return ? after_return->rmse : -1.0},
      {"after_return_max_m", after_return ? after_return->max : -1.0}};
}

// How a lost stretch ended: its stats.json name and the summary's words.
struct LostStretchEnding {
  const char* name;
  const char* words;
};

LostStretchEnding ending(RunStatistics::LostStretch::End end) {
  switch (end) {
    case RunStatistics::LostStretch::End::still_lost:
      return {"still_lost", "until the end (never tracked again)"};
    case RunStatistics::LostStretch::End::tracked_again:
      return {"tracked_again", "then tracked again"};
    case RunStatistics::LostStretch::End::map_restarted:
      return {"map_restarted", "then a new map was started"};
  }
  return {"?", "?"};
}

// Frames, speed, map size and what local mapping did (and the loops, when they are closed).
void print_frames_and_map(const RunReportInput& input, std::ostream& out) {
  const RunStatistics& stats = input.statistics;
  const MappingStats& mapping = input.mapping;
  const SystemOptions& system = input.options.system;
  const size_t processed = stats.processed();
  const size_t lost_count = stats.lost();
  const double seconds = input.seconds;
  char line[512];
  std::snprintf(line, sizeof(line),
                "frames:       %zu processed, %zu tracked, %zu without pose (lost_frames.txt)\n"
                "speed:        %.1f fps overall (%.1f s)\n"
                "median ms:    extraction %.2f, tracking %.2f (tracking thread CPU %.2f)\n"
                "map:          %zu keyframes, %zu map points; mapping queue max %zu, local BA "
                "%.0f ms total\n",
                processed, processed - lost_count, lost_count,
                seconds > 0 ? processed / seconds : 0.0, seconds, median(stats.extraction_ms),
                median(stats.tracking_ms), median(stats.tracking_cpu_ms), mapping.keyframes_in_map,
                mapping.map_points, mapping.max_queued_keyframes, mapping.local_ba_ms_total);
  out << line;
  std::string window =
      system.local_ba_keyframes > 0
          ? "the best " + std::to_string(system.local_ba_keyframes) + " covisible keyframes"
          : "every covisible keyframe";
  if (system.ba_tracking_factors > 0.0)
    window += fmt::format(", with tracking's factors (weight {:g})", system.ba_tracking_factors);
  std::snprintf(line, sizeof(line),
                "mapping:      %zu keyframes processed, %zu culled; points: %zu triangulated, "
                "%zu fused, %zu culled, %zu BA outlier observations removed; %zu local BAs cut "
                "short; local BA window: %s\n",
                mapping.processed_keyframes, mapping.keyframes_culled, mapping.points_triangulated,
                mapping.points_fused, mapping.points_culled, mapping.ba_outliers_removed,
                mapping.local_ba_cut_short, window.c_str());
  out << line;
  if (system.place.loop_closing)
    print_loop_stats(mapping, input.sensor == SensorType::monocular, out);
}

// How a monocular map started: loaded, after a two-view start, or never.
void print_monocular_start(const RunStatistics& stats, bool map_loaded, std::ostream& out) {
  char line[512];
  if (map_loaded) {
    const size_t tracked = stats.processed() - stats.lost();
    std::snprintf(line, sizeof(line),
                  "monocular:    map loaded (no two-view start); %zu of %zu frames tracked "
                  "(%.1f %%)\n",
                  tracked, stats.processed(),
                  stats.processed() > 0 ? 100.0 * tracked / stats.processed() : 0.0);
  } else if (stats.initialised_at()) {
    const size_t since = stats.processed_since_initialisation();
    std::snprintf(line, sizeof(line),
                  "monocular:    map started at frame %zu (%zu frames before it placed in the "
                  "first map); %zu of %zu frames tracked from there (%.1f %%), %zu map "
                  "restarts\n",
                  *stats.initialised_at(), stats.placed_before_initialisation(),
                  stats.tracked_since_initialisation(), since,
                  since > 0 ? 100.0 * stats.tracked_since_initialisation() / since : 0.0,
                  stats.map_restarts());
  } else {
    std::snprintf(line, sizeof(line),
                  "monocular:    the map never started (no two frames with enough parallax "
                  "and matches)\n");
  }
  out << line;
}

void print_longest_lost_stretch(const RunStatistics& stats, std::ostream& out) {
  const auto longest = stats.longest_lost_stretch();
  if (!longest) return;
  const size_t stretches = stats.lost_stretches();
  char line[512];
  std::snprintf(line, sizeof(line),
                "lost:         %zu stretch%s after the map started; the longest: frames "
                "%zu-%zu (%zu frames), %s\n",
                stretches, stretches == 1 ? "" : "es", longest->first_frame, longest->last_frame,
                longest->frames, ending(longest->end).words);
  out << line;
}

// The ATE of both trajectories against the sequence's ground truth, when it has one.
struct RunAte {
  std::optional<AteResult> tracked;
  std::optional<AteResult> refined;
};

RunAte report_ate(const RunReportInput& input, bool monocular, std::ostream& out) {
  RunAte result;
  const std::optional<Trajectory>& ground_truth = input.source.ground_truth();
  if (!ground_truth || input.estimate.size() < 3) return result;
  const std::tuple<const char*, const Trajectory*, std::optional<AteResult>*> evaluated[] = {
      {"trajectory.txt        ", &input.estimate, &result.tracked},
      {"trajectory_refined.txt", &input.refined, &result.refined}};
  char line[512];
  for (const auto& [name, poses, slot] : evaluated) {
    try {
      // A monocular map has its own scale: only a similarity aligns it.
      const AteResult ate = compute_ate(*ground_truth, *poses, AteOptions{.sim3 = monocular});
      std::snprintf(line, sizeof(line),
                    "ATE %s (%s aligned, %zu poses): RMSE %.4f m, mean %.4f m, median "
                    "%.4f m, max %.4f m%s\n",
                    name, monocular ? "Sim(3)" : "SE(3)", ate.error.count, ate.error.rmse,
                    ate.error.mean, ate.error.median, ate.error.max,
                    monocular ? (", scale " + std::to_string(ate.alignment.scale)).c_str() : "");
      out << line;
      *slot = ate;
    } catch (const Error& e) {
      out << "ATE " << name << ": not computed: " << e.what() << "\n";
    }
  }
  return result;
}

// Per-module timing and the mask ages, printed and written to stats.json.
struct ModuleTimings {
  TimingSummary extraction;
  TimingSummary semantic;
  TimingSummary semantic_wait;
  TimingSummary geometry;
  TimingSummary search;
  TimingSummary flow;
  TimingSummary tracking;
  TimingSummary mapping;
  TimingSummary mask_age;
  TimingSummary mask_latency;
};

ModuleTimings summarize_modules(const RunStatistics& stats) {
  return {.extraction = summarize(stats.extraction_ms),
          .semantic = summarize(stats.semantic_ms),
          .semantic_wait = summarize(stats.semantic_wait_ms),
          .geometry = summarize(stats.geometry_ms),
          .search = summarize(stats.geometry_search_ms),
          .flow = summarize(stats.flow_ms),
          .tracking = summarize(stats.tracking_ms),
          .mapping = summarize(stats.local_mapping_ms),
          .mask_age = summarize(stats.mask_age_frames),
          .mask_latency = summarize(stats.mask_latency_ms)};
}

// Per-module timing, the dynamic-feature totals and the arrival-to-pose latency.
void print_timing_and_dynamic(const RunReportInput& input, const ModuleTimings& t,
                              std::ostream& out) {
  const RunStatistics& stats = input.statistics;
  char line[512];
  std::snprintf(line, sizeof(line),
                "timing ms:    median/mean/p95  extraction %.1f/%.1f/%.1f  semantic inference "
                "%.1f/%.1f/%.1f (waited %.1f/%.1f/%.1f)\n"
                "              geometry %.1f/%.1f/%.1f (search %.1f)  flow+H %.1f  tracking "
                "%.1f/%.1f/%.1f  local BA %.1f/%.1f/%.1f\n",
                t.extraction.median, t.extraction.mean, t.extraction.p95, t.semantic.median,
                t.semantic.mean, t.semantic.p95, t.semantic_wait.median, t.semantic_wait.mean,
                t.semantic_wait.p95, t.geometry.median, t.geometry.mean, t.geometry.p95,
                t.search.median, t.flow.median, t.tracking.median, t.tracking.mean, t.tracking.p95,
                t.mapping.median, t.mapping.mean, t.mapping.p95);
  out << line;
  std::snprintf(line, sizeof(line),
                "dynamic:      mode %s; %zu keypoints tested, %zu flagged by geometry, %zu "
                "dropped before tracking, %zu map points culled; mask age median %.0f frames "
                "(%.0f ms), %zu frames without mask, %zu frames dropped by the real-time feed\n",
                to_string(input.options.system.dynamic.mode), stats.tested_points,
                stats.dynamic_points, stats.masked_keypoints, stats.culled_points,
                t.mask_age.median, t.mask_latency.median, stats.frames_without_mask,
                stats.realtime_dropped());
  out << line;
  if (!stats.arrival_to_pose_ms.empty()) {
    const LatencySummary arrival = summarize_latency(stats.arrival_to_pose_ms);
    std::snprintf(line, sizeof(line),
                  "latency:      arrival to pose median %.1f ms, p99 %.1f ms, max %.1f ms (%zu "
                  "frames)\n",
                  arrival.median, arrival.p99, arrival.max, arrival.count);
    out << line;
  }
}

// What the summary printed before stats.json is written: its members that are not read off
// the statistics again.
struct ReportedSections {
  RunAte ate;
  ModuleTimings timings;
  nlohmann::ordered_json blackout;    // null without a blackout
  nlohmann::ordered_json live_masks;  // null except for a live run with semantics
  FrameSourceStats source;
};

// stats.json's head: what ran, on what, and how many frames.
nlohmann::ordered_json run_json(const RunReportInput& input) {
  const RunStatistics& stats = input.statistics;
  const SystemOptions& system = input.options.system;
  return {{"sequence", input.source.name()},
          {"version", version_string()},
          {"config", input.config_file.string()},
          {"sensor", to_string(input.sensor)},
          {"mode", to_string(system.dynamic.mode)},
          {"realtime", system.dynamic.realtime},
          {"interrupted", input.interrupted},
          {"frames", stats.processed()},
          {"lost_frames", stats.lost()},
          {"relocalisations", stats.relocalisations()}};
}

// Every run setting the System got, by its Python keyword (session/run_option_table.h).
nlohmann::ordered_json settings_json(const RunReportInput& input) {
  nlohmann::ordered_json json = nlohmann::ordered_json::object();
  for (const auto& [keyword, value] : input.options.settings) json[keyword] = value;
  return json;
}

nlohmann::ordered_json monocular_json(const RunStatistics& stats, bool map_loaded) {
  return {{"initialised_at_frame", stats.initialised_at()
                                       ? nlohmann::ordered_json(*stats.initialised_at())
                                       : nlohmann::ordered_json(nullptr)},
          {"frames_since_initialisation", stats.processed_since_initialisation()},
          {"tracked_since_initialisation", stats.tracked_since_initialisation()},
          {"placed_before_initialisation", stats.placed_before_initialisation()},
          {"map_restarts", stats.map_restarts()},
          {"map_loaded", map_loaded}};
}

nlohmann::ordered_json lost_stretches_json(const RunStatistics& stats) {
  nlohmann::ordered_json longest_lost = nullptr;
  if (const auto longest = stats.longest_lost_stretch()) {
    longest_lost = {{"first_frame", longest->first_frame},
                    {"last_frame", longest->last_frame},
                    {"frames", longest->frames},
                    {"end", ending(longest->end).name}};
  }
  return {{"count", stats.lost_stretches()}, {"longest", longest_lost}};
}

// Whether local BA's cost grows with the map: its median CPU time over the first and the last
// sixth of the frames processed (a 3000-frame run: frames 0-500 and 2500-3000), and their ratio.
// CPU time, not wall time: a machine busier at the end than at the start must not look like
// growth.
void add_local_ba_growth(const RunStatistics& stats, nlohmann::ordered_json& json) {
  const size_t sixth = stats.processed() / 6;
  std::vector<double> first;
  std::vector<double> last;
  for (size_t i = 0; i < stats.local_mapping_ms.size(); ++i) {
    const double cpu_ms = stats.local_mapping_cpu_ms[i];
    if (stats.local_mapping_at[i] <= sixth) first.push_back(cpu_ms);
    if (stats.local_mapping_at[i] > stats.processed() - sixth) last.push_back(cpu_ms);
  }
  if (first.empty() || last.empty()) return;
  const double first_median = summarize(first).median;
  const double last_median = summarize(last).median;
  json["local_mapping_cpu"] = to_json(summarize(stats.local_mapping_cpu_ms));
  json["local_mapping_cpu_first_sixth"] = to_json(summarize(first));
  json["local_mapping_cpu_last_sixth"] = to_json(summarize(last));
  json["local_mapping_cpu_growth"] = first_median > 0.0 ? last_median / first_median : 0.0;
}

nlohmann::ordered_json timing_json(const RunStatistics& stats, const ModuleTimings& t) {
  nlohmann::ordered_json json = {
      {"extraction", to_json(t.extraction)},       {"semantic", to_json(t.semantic)},
      {"semantic_wait", to_json(t.semantic_wait)}, {"geometry", to_json(t.geometry)},
      {"geometry_search", to_json(t.search)},      {"flow_homography", to_json(t.flow)},
      {"tracking", to_json(t.tracking)},           {"local_mapping", to_json(t.mapping)}};
  if (!stats.observer_cpu_ms.empty())
    json["viewer_hooks_cpu"] = to_json(summarize(stats.observer_cpu_ms));
  add_local_ba_growth(stats, json);
  return json;
}

// The map, local mapping's window and the loops.
void add_map_json(const RunReportInput& input, nlohmann::ordered_json& json) {
  const MappingStats& mapping = input.mapping;
  const SystemOptions& system = input.options.system;
  // How the threads shared the cores, to read beside the latency.
  // Written from the thread that tracked: the nice value the run's tracking had.
  json["scheduling"] = {{"tracking_nice", this_thread_nice()},
                        {"background_thread_nice", system.background_thread_nice},
                        {"opencv_threads", cv::getNumThreads()},
                        {"blas_threads", blas_threads()},
                        {"segment_every", system.dynamic.segment_every},
                        {"local_ba_keyframes", system.local_ba_keyframes},
                        {"local_ba_fixed_keyframes", system.local_ba_fixed_keyframes},
                        {"ba_tracking_factors", system.ba_tracking_factors}};
  json["map"] = {{"keyframes", mapping.keyframes_in_map},
                 {"map_points", mapping.map_points},
                 {"keyframes_processed", mapping.processed_keyframes},
                 {"local_ba_cut_short", mapping.local_ba_cut_short}};
  json["loops"] = {{"enabled", system.place.loop_closing},
                   {"closed", mapping.loops_closed},
                   {"maps_merged", mapping.map_merges.size()},
                   {"global_ba_applied", mapping.global_ba_applied}};
  if (mapping.loops_closed > 0) {
    // Map units: metres except for a monocular map; the scale is 1 except for a monocular map.
    json["loops"]["last_correction"] = {{"moved", mapping.last_loop_correction_m},
                                        {"resized", mapping.last_loop_correction_scale}};
  }
}

void add_ate_json(const RunAte& ates, bool monocular, nlohmann::ordered_json& json) {
  const std::pair<const char*, const std::optional<AteResult>*> evaluated[] = {
      {"ate", &ates.tracked}, {"ate_refined", &ates.refined}};
  for (const auto& [key, ate] : evaluated) {
    if (!*ate) continue;
    json[key] = {{"alignment", monocular ? "sim3" : "se3"},
                 {"scale", (*ate)->alignment.scale},
                 {"rmse", (*ate)->error.rmse},
                 {"mean", (*ate)->error.mean},
                 {"median", (*ate)->error.median},
                 {"max", (*ate)->error.max},
                 {"poses", (*ate)->error.count}};
  }
}

// One line on the people tracked (people.csv), with their score where the sequence has a truth.
void print_people(const nlohmann::ordered_json& people, std::ostream& out) {
  out << "people:       " << people["tracks"].get<int>() << " tracks, "
      << people["rows"].get<size_t>() << " rows in people.csv";
  if (people.contains("score")) {
    const nlohmann::ordered_json& score = people["score"];
    out << fmt::format(
        "; {:.1f} % of person-frames tracked, median error {:.0f} mm, {} id switches, "
        "{:.1f} % false",
        score["tracked_percent"].get<double>(), score["position_error_mm_median"].get<double>(),
        score["id_switches"].get<int>(), score["false_percent"].get<double>());
  }
  out << "\n";
}

nlohmann::ordered_json stats_json(const RunReportInput& input, const ReportedSections& reported) {
  const RunStatistics& stats = input.statistics;
  const SystemOptions& system = input.options.system;
  const bool monocular = input.sensor == SensorType::monocular;
  nlohmann::ordered_json json = run_json(input);
  if (!reported.blackout.is_null()) json["blackout"] = reported.blackout;
  if (input.requested_mode != system.dynamic.mode)
    json["mode_requested"] = to_string(input.requested_mode);
  json["settings"] = settings_json(input);
  if (monocular) json["monocular"] = monocular_json(stats, !system.map_file.empty());
  json["lost_stretches"] = lost_stretches_json(stats);
  json["realtime_dropped_frames"] = stats.realtime_dropped();
  // How the input ended: a camera that was unplugged or fell silent says so here.
  json["input"] = {{"dropped_frames", reported.source.dropped},
                   {"disconnected", reported.source.disconnected},
                   {"end_reason", reported.source.end_reason}};
  json["seconds"] = input.seconds;
  json["fps"] = input.seconds > 0 ? static_cast<double>(stats.processed()) / input.seconds : 0.0;
  json["timing_ms"] = timing_json(stats, reported.timings);
  json["dynamic"] = {{"tested_points", stats.tested_points},
                     {"dynamic_points", stats.dynamic_points},
                     {"masked_keypoints", stats.masked_keypoints},
                     {"culled_map_points", stats.culled_points},
                     {"frames_without_mask", stats.frames_without_mask}};
  json["mask_latency"] = {{"frames", to_json(reported.timings.mask_age)},
                          {"ms", to_json(reported.timings.mask_latency)}};
  if (!reported.live_masks.is_null()) json["live_masks"] = reported.live_masks;
  // The real-time targets from the camera's point of view: a frame is tracked before the
  // next one arrives (arrival to pose, ms; empty without --realtime or a camera) and the mask it
  // used is at most 2 frames old (frames between the masked frame and this one).
  const LatencySummary arrival_to_pose = summarize_latency(stats.arrival_to_pose_ms);
  json["latency"] = {{"arrival_to_pose_ms", to_json(arrival_to_pose)},
                     {"mask_age_frames", to_json(summarize_latency(stats.mask_age_frames))}};
  add_map_json(input, json);
  json["atlas"] = atlas_json(input.atlas);
  add_ate_json(reported.ate, monocular, json);
  json["occupancy"] = input.occupancy != nullptr ? *input.occupancy : nlohmann::ordered_json();
  if (input.people) json["people"] = *input.people;
  return json;
}

}  // namespace

void write_run_report(const RunReportInput& input, std::ostream& out) {
  const std::filesystem::path& out_dir = input.options.outputs.folder;
  const bool monocular = input.sensor == SensorType::monocular;
  print_frames_and_map(input, out);
  // A loaded map (--load-map) is there from the first frame: no two-view start to report.
  const bool map_loaded = !input.options.system.map_file.empty();
  if (monocular) print_monocular_start(input.statistics, map_loaded, out);
  print_longest_lost_stretch(input.statistics, out);
  print_atlas(input.atlas, out);
  out << "output:       " << (out_dir / "trajectory_refined.txt").string()
      << " (the file to evaluate, " << input.refined.size()
      << " poses), trajectory.txt (as tracked), keyframes.txt,\n"
      << "              lost_frames.txt, timing.csv, run_config.yaml (the config used)\n";
  ReportedSections reported;
  reported.ate = report_ate(input, monocular, out);
  if (input.options.blackout)
    reported.blackout = report_blackout(input, *input.options.blackout, reported.ate.tracked, out);
  reported.timings = summarize_modules(input.statistics);
  print_timing_and_dynamic(input, reported.timings, out);
  reported.live_masks = report_live_masks(input, out);
  reported.source = input.source.stats();
  if (reported.source.disconnected) out << "input:        " << reported.source.end_reason << "\n";
  if (input.people) print_people(*input.people, out);

  const nlohmann::ordered_json json = stats_json(input, reported);
  std::ofstream file = open_output(out_dir / "stats.json");
  // Paths are not always UTF-8 (a Latin-1 folder name); replace invalid bytes instead of
  // throwing, so the summary is always written.
  file << json.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
  out << "stats:        " << (out_dir / "stats.json").string() << "\n";
}

}  // namespace pspslam
