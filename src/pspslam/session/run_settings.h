#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <utility>

#include "pspslam/occupancy/occupancy_options.h"
#include "pspslam/system/system.h"

namespace pspslam {

// Nice increment of the background threads in live runs: the caller thread must track each frame
// before the next one arrives, so the background work yields the core
// (docs/decisions/realtime-nice.md).
inline constexpr int kLiveBackgroundNice = 10;
// Nice value a live run asks for its tracking thread (and the threads started from it, whose
// background ones then lower theirs by kLiveBackgroundNice): beside busy programs of normal
// priority on two cores, tracking at nice 0 gets too little of a core to keep up with 30 Hz
// (docs/decisions/live-priority.md). Granted to root or with CAP_SYS_NICE only.
inline constexpr int kLiveFramePathNice = -10;
// Local BA window of live runs: the best 10 covisible keyframes. On two cores the whole covisible
// set of a small room leaves local BA cut short, and the capped window keeps up. Offline runs keep
// ORB-SLAM2's whole window, which gives the better final trajectory.
inline constexpr int kLiveLocalBaKeyframes = 10;
// The atlas: seconds lost, with every relocalisation failing, before a new map starts
// (TrackerOptions::new_map_after_seconds). A live run waits longer: while the network lags, the
// crowd can keep tracking lost for over a second before relocalisation finds the map again, and a
// new map started meanwhile leaves the frames after it in another world frame until a merge
// (docs/decisions/atlas.md).
inline constexpr double kNewMapAfterSeconds = 1.0;
inline constexpr double kLiveNewMapAfterSeconds = 3.0;

// The run settings that shape the System: `pspslam run`'s flags and the Python module's keywords
// of the same names (declared once, session/run_option_table.h), with their defaults. Empty
// optionals take the run's default.
struct RunSettings {
  std::string mode = "auto";  // off | semantic | geometry | full | exhaustive | auto
  std::optional<std::filesystem::path> model;           // none: the shipped model
  std::optional<std::filesystem::path> vocabulary;      // none: the shipped vocabulary
  std::optional<std::filesystem::path> semantic_masks;  // none: the network segments the frames
  std::optional<std::filesystem::path> load_map;
  bool localization = false;  // used with load_map only
  bool realtime = false;
  // Frames from a live source as they arrive (`run --camera`, Python's live=True): live as with
  // realtime, and each frame waits for local mapping only.
  bool live_camera = false;
  bool local_mapping = true;
  bool relocalization = true;
  // 0: never start a new map; none: kLiveNewMapAfterSeconds when live, else kNewMapAfterSeconds.
  std::optional<double> new_map_after;
  std::string loop_closing = "auto";  // on | off | auto
  int mask_margin = 5;
  int segment_every = 1;
  int cull_hits = 3;
  std::string cull_evidence = "off";  // off | mask | seen-through (CullingEvidence)
  double keyframe_ratio = KeyFramePolicyOptions{}.tracked_ratio_to_reference;
  bool due_keyframes = false;
  std::optional<int> local_ba_keyframes;  // none: kLiveLocalBaKeyframes when live, else 0 (all)
  int local_ba_fixed_keyframes = 0;       // 0: every keyframe that sees the window's points
  double ba_tracking_factors = 0.0;       // weight of tracking's relative poses in local BA
  std::optional<int> background_nice;     // none: kLiveBackgroundNice when live, else 0
  std::optional<std::pair<double, double>> motion_prior;  // millimetres, degrees
  // What a live run does when its network falls behind (each acts with realtime only).
  std::string semantic_pace = "off";                   // on | off
  std::optional<std::filesystem::path> smaller_model;  // none: the shipped one with its model
  std::string stale_masks = "homography";              // homography | flow
  int stale_mask_growth = MaskPropagationParams{}.max_growth_px;
  std::string stale_geometry = "on";       // on | off
  std::string late_mask_culling = "on";    // on | off
  std::string judged_points_first = "on";  // on | off
  std::string mover_guard = "off";         // on | off
  std::string semantic_delay_ms;           // fault injection: MS | random:MIN:MAX; empty: none
  long long semantic_delay_seed = 1;
  // The occupancy map of the static scene, built beside the run (session/occupancy_run.h).
  bool occupancy = false;
  double occupancy_resolution = OccupancyOptions{}.resolution_m;
  double occupancy_max_range = OccupancyOptions{}.max_range_m;
  std::string occupancy_masks = "on";     // on | off
  std::string occupancy_clearing = "on";  // on | off

  // A live run must keep up with its frames, so its background work yields and its BA is capped.
  bool live() const { return realtime || live_camera; }
};

// How a run's messages name its settings: the CLI's flags, or the Python keywords (an exception
// with the model's own error is the whole message there, and auto falls back without a warning).
struct SettingNames {
  const char* mode = "--dynamic";
  const char* semantic_masks = "--semantic-masks";
  bool explain_model = true;  // say how to get a missing model; warn when auto falls back
  bool keywords = false;      // name every option by its Python keyword instead of its flag
};

// The dynamic mode the settings ask for: auto = full when the segmentation model loads, else
// geometry; a semantic mode asked for by name needs its model, and masks from files need a mode
// that uses them. Throws Error naming the setting otherwise.
DynamicMode choose_mode(const RunSettings& settings, const std::filesystem::path& model,
                        const SettingNames& names = {});

// The SystemOptions of a run with these settings. Deterministic unless `realtime` or
// `live_camera`: each frame waits for its mask and the whole back end.
SystemOptions system_options(const RunSettings& settings, const SettingNames& names = {});

}  // namespace pspslam
