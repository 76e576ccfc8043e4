#pragma once

#include <CLI/CLI.hpp>

#include <string>

#include "pspslam/core/error.h"
#include "pspslam/session/occupancy_run.h"

namespace pspslam::cli {

// `pspslam run`'s own occupancy flags (session/occupancy_run.h): the outputs, the grid's band and
// the scoring. The map's options (--occupancy, --occupancy-*) are in the run option table.
struct OccupancyFlags {
  std::string export_octomap;
  std::string export_grid;
  double min_height = GridOptions{}.min_height_m;
  double max_height = GridOptions{}.max_height_m;
  std::string floor = "auto";
  std::string truth;
};

inline void add_occupancy_options(CLI::App* app, OccupancyFlags& flags) {
  app->add_option("--export-octomap", flags.export_octomap,
                  "write the occupancy map at the final keyframe poses as an OctoMap binary "
                  "(.bt, octovis reads it); implies --occupancy");
  app->add_option("--export-grid", flags.export_grid,
                  "write a 2D occupancy grid in ROS map_server format to this YAML file and the "
                  "PGM beside it: the map over the height band above the floor; implies "
                  "--occupancy");
  app->add_option("--grid-min-height", flags.min_height,
                  "lowest height above the floor the 2D grid sees (metres)")
      ->capture_default_str();
  app->add_option("--grid-max-height", flags.max_height,
                  "highest height above the floor the 2D grid sees: the robot's height (metres)")
      ->capture_default_str();
  app->add_option("--grid-floor", flags.floor,
                  "the floor's height along the first camera's up axis (-y), metres; auto: the "
                  "largest level plane below the cameras in the map")
      ->capture_default_str();
  app->add_option("--occupancy-truth", flags.truth,
                  "score the occupancy map against a synthetic sequence's truth folder "
                  "(SEQUENCE/occupancy_truth, from pspslam synth --occupancy-truth); scores in "
                  "stats.json; implies --occupancy");
}

// The occupancy options the flags and the table's settings ask for; throws pspslam::Error naming
// a bad flag.
inline OccupancyRunOptions occupancy_options(const OccupancyFlags& flags,
                                             const RunSettings& settings) {
  OccupancyRunOptions options = occupancy_run_options(settings);
  options.enabled = options.enabled || !flags.export_octomap.empty() ||
                    !flags.export_grid.empty() || !flags.truth.empty();
  options.export_octomap = flags.export_octomap;
  options.export_grid = flags.export_grid;
  options.truth = flags.truth;
  options.grid.min_height_m = flags.min_height;
  options.grid.max_height_m = flags.max_height;
  if (flags.floor != "auto") {
    try {
      size_t used = 0;
      options.grid.floor_height_m = std::stod(flags.floor, &used);
      if (used != flags.floor.size()) throw std::invalid_argument(flags.floor);
    } catch (const std::exception&) {
      throw Error("flag --grid-floor: expected a height in metres or 'auto', got '" + flags.floor +
                  "'");
    }
  }
  // A bad value is refused even when no occupancy output was asked for.
  OccupancyRunOptions checked = options;
  checked.enabled = true;
  checked.truth.clear();
  checked.validate();
  options.validate();
  return options;
}

}  // namespace pspslam::cli
