#pragma once

#include <cstddef>

#include "pspslam/core/types.h"
#include "pspslam/occupancy/occupancy_grid.h"
#include "pspslam/occupancy/occupancy_map.h"
#include "pspslam/synth/occupancy_truth.h"

namespace pspslam {

// An occupancy map against a synthetic sequence's truth (synth/occupancy_truth.h), placed in the
// truth's frame by the SE(3) alignment of the keyframe trajectory onto the exact camera poses.
struct OccupancyScore {
  size_t occupied = 0;        // occupied voxels of the map
  double precision = 0;       // occupied voxels within one cell of a static truth cell
  size_t seen = 0;            // static truth cells the camera saw
  double recall = 0;          // seen cells with an occupied voxel within one voxel
  size_t swept = 0;           // cells the people swept through
  size_t ghosts = 0;          // occupied voxels in swept cells, not within one cell of a static one
  double ghost_fraction = 0;  // ghosts / swept
  size_t grid_known = 0;      // grid cells free or occupied
  double grid_agreement = 0;  // known grid cells whose state the truth's band agrees with
  double alignment_rmse_m = 0;
};

// `grid` may be null (no grid scores); `options` gives its height band (the truth's floor is
// z = 0). Throws pspslam::Error when the keyframes cannot be aligned to the truth.
OccupancyScore score_occupancy(const OccupancyMap& map, const OccupancyGrid* grid,
                               const GridOptions& options, const Trajectory& keyframes,
                               const OccupancyTruth& truth);

}  // namespace pspslam
