#include "pspslam/occupancy/occupancy_score.h"

#include "pspslam/eval/ate.h"

namespace pspslam {
namespace {

// Whether the truth holds static geometry over (x, y) within the height band.
bool truth_column_occupied(const OccupancyTruth& truth, const Eigen::Vector3d& point,
                           const GridOptions& options) {
  for (double z = options.min_height_m; z <= options.max_height_m; z += truth.resolution / 2.0) {
    if (truth.static_near(truth.cell_of({point.x(), point.y(), z}))) return true;
  }
  return false;
}

void score_grid(const OccupancyGrid& grid, const GridOptions& options, const Alignment& alignment,
                const OccupancyTruth& truth, OccupancyScore& score) {
  size_t agree = 0;
  for (int row = 0; row < grid.height; ++row) {
    for (int column = 0; column < grid.width; ++column) {
      const std::int8_t state = grid.at(column, row);
      if (state == kGridUnknown) continue;
      ++score.grid_known;
      const Eigen::Vector3d in_grid(grid.origin.x() + (column + 0.5) * grid.resolution,
                                    grid.origin.y() + (row + 0.5) * grid.resolution, 0.0);
      const Eigen::Vector3d in_truth = alignment.apply(grid.T_world_grid * in_grid);
      agree += truth_column_occupied(truth, in_truth, options) == (state == kGridOccupied);
    }
  }
  score.grid_agreement = score.grid_known > 0
                             ? static_cast<double>(agree) / static_cast<double>(score.grid_known)
                             : 0.0;
}

}  // namespace

OccupancyScore score_occupancy(const OccupancyMap& map, const OccupancyGrid* grid,
                               const GridOptions& options, const Trajectory& keyframes,
                               const OccupancyTruth& truth) {
  const AteResult ate = compute_ate(truth.camera_poses, keyframes);
  const Alignment& alignment = ate.alignment;
  OccupancyScore score;
  score.alignment_rmse_m = ate.error.rmse;
  size_t correct = 0;
  map.for_each_voxel([&](const Eigen::Vector3d& centre, bool occupied) {
    if (!occupied) return;
    ++score.occupied;
    const VoxelIndex cell = truth.cell_of(alignment.apply(centre));
    const bool is_static = truth.static_near(cell);
    correct += is_static;
    score.ghosts += !is_static && truth.swept_cells.contains(cell);
  });
  score.precision =
      score.occupied > 0 ? static_cast<double>(correct) / static_cast<double>(score.occupied) : 0;
  size_t recalled = 0;
  for (const VoxelIndex& cell : truth.seen_cells)
    recalled += map.occupied_near(alignment.inverse_apply(truth.centre_of(cell)));
  score.seen = truth.seen_cells.size();
  score.recall =
      score.seen > 0 ? static_cast<double>(recalled) / static_cast<double>(score.seen) : 0;
  score.swept = truth.swept_cells.size();
  score.ghost_fraction =
      score.swept > 0 ? static_cast<double>(score.ghosts) / static_cast<double>(score.swept) : 0;
  if (grid != nullptr) score_grid(*grid, options, alignment, truth, score);
  return score;
}

}  // namespace pspslam
