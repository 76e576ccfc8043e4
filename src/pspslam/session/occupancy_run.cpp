#include "pspslam/session/occupancy_run.h"

#include <set>
#include <utility>

#include "pspslam/core/error.h"
#include "pspslam/occupancy/occupancy_grid.h"
#include "pspslam/occupancy/occupancy_score.h"
#include "pspslam/synth/occupancy_truth.h"

namespace pspslam {
namespace {

nlohmann::ordered_json score_json(const OccupancyScore& score) {
  return {{"occupied_voxels", score.occupied},
          {"precision", score.precision},
          {"seen_cells", score.seen},
          {"recall", score.recall},
          {"swept_cells", score.swept},
          {"ghost_voxels", score.ghosts},
          {"ghost_fraction", score.ghost_fraction},
          {"grid_known_cells", score.grid_known},
          {"grid_agreement", score.grid_agreement},
          {"alignment_rmse_m", score.alignment_rmse_m}};
}

nlohmann::ordered_json grid_json(const OccupancyGrid& grid, size_t seen_through_cells) {
  nlohmann::ordered_json pose = nlohmann::ordered_json::array();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) pose.push_back(grid.T_world_grid.matrix()(r, c));
  return {{"width", grid.width},
          {"height", grid.height},
          {"occupied_cells", grid.count(kGridOccupied)},
          {"free_cells", grid.count(kGridFree)},
          {"unknown_cells", grid.count(kGridUnknown)},
          {"occupied_cells_seen_through", seen_through_cells},
          {"floor_height_m", grid.floor.height},
          {"floor_from_map", grid.floor.from_map},
          {"floor_support_voxels", grid.floor.support},
          {"T_world_grid", pose}};
}

// Grid cells that are occupied and hold an occupied voxel, within the band, that a later
// keyframe's rays passed through.
size_t occupied_cells_seen_through(const OccupancyGrid& grid, const GridOptions& options,
                                   const std::vector<Eigen::Vector3d>& seen_through) {
  std::set<std::pair<int, int>> cells;
  const Pose T_grid_world = grid.T_world_grid.inverse();
  for (const Eigen::Vector3d& centre : seen_through) {
    const double height = (T_grid_world * centre).z();
    int column = 0, row = 0;
    if (height < options.min_height_m || height > options.max_height_m) continue;
    if (grid.cell_of(centre, column, row) && grid.at(column, row) == kGridOccupied)
      cells.emplace(column, row);
  }
  return cells.size();
}

}  // namespace

void OccupancyRunOptions::validate() const {
  if (!enabled) return;
  map.validate();
  grid.validate();
  if (!truth.empty() && !std::filesystem::is_regular_file(truth / "static.txt"))
    throw Error("flag --occupancy-truth: " + truth.string() +
                " holds no static.txt (pspslam synth --occupancy-truth RES writes it)");
}

OccupancyRunOptions occupancy_run_options(const RunSettings& settings) {
  OccupancyRunOptions options;
  options.enabled = settings.occupancy;
  options.map.resolution_m = settings.occupancy_resolution;
  options.map.max_range_m = settings.occupancy_max_range;
  options.map.use_masks = settings.occupancy_masks == "on";
  options.map.clearing = settings.occupancy_clearing == "on";
  return options;
}

OccupancyRun::OccupancyRun(const PinholeCamera& camera, OccupancyRunOptions options)
    : options_(std::move(options)), mapper_(camera, options_.map) {}

void OccupancyRun::add_keyframe(std::shared_ptr<const KeyFrame> keyframe, const cv::Mat& depth,
                                const cv::Mat& dynamic_mask) {
  mapper_.add_keyframe(std::move(keyframe), depth, dynamic_mask);
}

OccupancyGrid OccupancyRun::live_grid() const {
  if (mapper_.camera_centres().empty()) return {};
  return grid(options_.grid);
}

OccupancyGrid OccupancyRun::grid(const GridOptions& band) const {
  OccupancyGrid grid;
  const std::vector<Eigen::Vector3d> cameras = mapper_.camera_centres();
  mapper_.read([&](const OccupancyMap& map) {
    grid = make_grid(map, find_floor(map, cameras, band), band);
  });
  return grid;
}

void OccupancyRun::finish(const Trajectory& keyframes, std::ostream& out) {
  mapper_.finish();
  const OccupancyStats stats = mapper_.stats();
  if (!options_.export_octomap.empty()) {
    mapper_.read([&](const OccupancyMap& map) {
      map.write_binary(options_.export_octomap);
      out << "occupancy:    " << options_.export_octomap.string() << " (OctoMap, "
          << map.resolution() << " m voxels)\n";
    });
  }
  const OccupancyGrid grid = this->grid(options_.grid);
  const size_t seen_through =
      occupied_cells_seen_through(grid, options_.grid, mapper_.seen_through());
  if (!options_.export_grid.empty()) {
    write_map_server(grid, options_.export_grid);
    out << "occupancy:    " << options_.export_grid.string() << " (map_server grid " << grid.width
        << "x" << grid.height << ", " << grid.count(kGridOccupied) << " occupied cells, "
        << seen_through << " of them seen through by later keyframes)\n";
  }
  const double per_keyframe =
      stats.inserted > 0 ? stats.insert_ms_total / static_cast<double>(stats.inserted) : 0.0;
  json_ = {
      {"resolution_m", options_.map.resolution_m},
      {"masks", options_.map.use_masks},
      {"clearing", options_.map.clearing},
      {"keyframes", stats.keyframes},
      {"inserted_live", stats.inserted},
      {"insert_ms_per_keyframe", per_keyframe},
      {"insert_cpu_ms_per_keyframe",
       stats.inserted > 0 ? stats.insert_cpu_ms_total / static_cast<double>(stats.inserted) : 0.0},
      {"live_rebuilds", stats.live_rebuilds},
      {"live_rebuild_ms_total", stats.rebuild_ms_total},
      {"final_rebuild_ms", stats.final_rebuild_ms},
      {"final_rebuild_ms_per_keyframe",
       stats.keyframes > 0 ? stats.final_rebuild_ms / static_cast<double>(stats.keyframes) : 0.0},
      {"memory_bytes", stats.map_bytes + stats.scan_bytes},
      {"map_bytes", stats.map_bytes},
      {"scan_bytes", stats.scan_bytes},
      {"grid", grid_json(grid, seen_through)},
      {"score", nullptr}};
  if (!options_.truth.empty()) {
    try {
      const OccupancyTruth truth = read_occupancy_truth(options_.truth);
      mapper_.read([&](const OccupancyMap& map) {
        json_["score"] = score_json(score_occupancy(map, &grid, options_.grid, keyframes, truth));
      });
    } catch (const Error& e) {
      out << "occupancy:    not scored: " << e.what() << "\n";
    }
  }
}

}  // namespace pspslam
