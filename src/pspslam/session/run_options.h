#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "pspslam/io/sequence_source.h"
#include "pspslam/session/occupancy_run.h"
#include "pspslam/system/system.h"

namespace pspslam {

// Frames first .. first + count - 1 of a run (`pspslam run --blackout FROM:COUNT`).
struct FrameRange {
  size_t first = 0;
  size_t count = 0;
  size_t end() const { return first + count; }
  bool covers(size_t index) const { return index >= first && index < end(); }
};

// Where a run writes. Empty paths are not written.
struct RunOutputs {
  std::filesystem::path folder = "pspslam_out";  // trajectory.txt, timing.csv, stats.json, ...
  std::filesystem::path save_map;                // binary map (persistence/)
  std::filesystem::path export_map;              // static map points, PLY
  std::filesystem::path export_dense;            // dense static cloud, PLY
  // Per-frame pictures (frame_images.h), one file per processed frame named after its colour
  // image: the final dynamic mask (8-bit PNG, 255 = dynamic) and the keypoint overlay.
  std::filesystem::path masks;
  std::filesystem::path overlays;
  // `--trajectory-format kitti`: also write trajectory_kitti.txt (online, the file to evaluate)
  // and trajectory_refined_kitti.txt in KITTI odometry format (3x4 row-major camera-to-world per
  // tracked frame, in frame order).
  bool kitti_trajectory = false;
};

// Checks every output path and creates the folders (core/output_paths.h) before any work, so a
// run never computes for minutes and then fails to write. Errors name the CLI flag of the path.
void prepare_run_outputs(const RunOutputs& outputs);
// The same for the occupancy map's files (--export-octomap, --export-grid), after checking its
// options.
void prepare_occupancy_outputs(const OccupancyRunOptions& occupancy);

// One run of the system (`pspslam run`).
struct RunOptions {
  // The input, one of three (session/run_input.h opens it): a recorded sequence folder, a live
  // camera (`--camera freenect[:INDEX]`) or a video file or camera index (`--video`).
  std::filesystem::path sequence;
  std::string camera;
  std::string video;
  // Config YAML; none: SEQUENCE/config.yaml (io/sequence_setup.h) or the camera's preset.
  std::optional<std::filesystem::path> config;
  // `pspslam run --sensor`: overrides the config's camera.type (io/sequence_setup.h).
  std::optional<SensorType> sensor;
  // A recorded sequence starts at this frame (`--start-frame`; frames keep their positions).
  size_t start_frame = 0;
  size_t max_frames = 0;  // 0 = all
  // `pspslam run --preload` (with --realtime): decode every frame before the paced replay starts
  // (io/sequence_source.h).
  Preload preload = Preload::automatic;
  // Frames fed as black images without depth: tracking is really lost (relocalisation tests).
  std::optional<FrameRange> blackout;
  RunOutputs outputs;
  SystemOptions system;
  // The run settings the System got (session/run_option_table.h effective_settings): stats.json's
  // "settings", as Python's System.settings reports them.
  std::vector<std::pair<std::string, std::string>> settings;
  OccupancyRunOptions occupancy;  // the occupancy map and its exports
  bool progress = true;           // progress bar on stderr
};

// How a run ended (the CLI maps it to an exit status).
enum class RunOutcome {
  completed,
  interrupted,    // Ctrl-C / SIGTERM: the outputs hold every frame processed so far
  never_started,  // the whole sequence ran and no frame ever started a map
  disconnected,   // the camera stopped delivering (unplugged): the outputs hold every frame so far
};

}  // namespace pspslam
