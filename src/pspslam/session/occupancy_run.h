#pragma once

#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <ostream>

#include "pspslam/camera/pinhole_camera.h"
#include "pspslam/core/types.h"
#include "pspslam/occupancy/occupancy_grid.h"
#include "pspslam/occupancy/occupancy_mapper.h"
#include "pspslam/occupancy/occupancy_options.h"
#include "pspslam/session/run_settings.h"

namespace pspslam {

class KeyFrame;

// `pspslam run --occupancy` and its outputs.
struct OccupancyRunOptions {
  bool enabled = false;  // --occupancy, or implied by --export-octomap / --export-grid
  OccupancyOptions map;
  GridOptions grid;
  std::filesystem::path export_octomap;  // OctoMap binary (.bt)
  std::filesystem::path export_grid;     // map_server YAML, PGM beside it
  // A synthetic sequence's occupancy_truth/ (pspslam synth --occupancy-truth): the map is scored
  // against it in stats.json.
  std::filesystem::path truth;

  // Throws pspslam::Error naming the flag of a bad value; checks the truth folder exists.
  void validate() const;
};

// What the run settings ask of the map (--occupancy and the --occupancy-* options, shared with
// Python's keywords); the outputs and the grid's band are left at their defaults.
OccupancyRunOptions occupancy_run_options(const RunSettings& settings);

// The occupancy map of one run: built while it goes (OccupancyMapper), then rebuilt at the final
// poses, exported, counted (occupied grid cells later keyframes saw through) and scored.
class OccupancyRun {
 public:
  OccupancyRun(const PinholeCamera& camera, OccupancyRunOptions options);

  // A new keyframe with the frame's depth and final dynamic mask (shared, not copied).
  void add_keyframe(std::shared_ptr<const KeyFrame> keyframe, const cv::Mat& depth,
                    const cv::Mat& dynamic_mask);
  // After the system has shut down: the final map, the exports and the scores (keyframes: the
  // final keyframe trajectory, for the alignment to the truth). Prints a line per output.
  void finish(const Trajectory& keyframes, std::ostream& out);
  // The 2D grid of the map as it is now, under the map's lock (any thread; the live viewer's
  // layer). Empty (width 0) while the map holds nothing.
  OccupancyGrid live_grid() const;
  // stats.json's "occupancy" member (after finish()).
  const nlohmann::ordered_json& json() const { return json_; }
  // The 2D grid over this band of the map as it stands (the final map after finish()).
  OccupancyGrid grid(const GridOptions& band) const;
  const OccupancyMapper& mapper() const { return mapper_; }

 private:
  OccupancyRunOptions options_;
  OccupancyMapper mapper_;
  nlohmann::ordered_json json_;
};

}  // namespace pspslam
