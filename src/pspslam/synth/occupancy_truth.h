#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <unordered_set>

#include "pspslam/core/types.h"
#include "pspslam/synth/scene.h"

namespace pspslam {

// A cell of a regular grid of cubes of side `resolution` in the synthetic room's world frame
// (z up, floor at z = 0): cell (i, j, k) spans [i r, (i + 1) r) x [j r, ...) x [k r, ...).
struct VoxelIndex {
  int x = 0, y = 0, z = 0;
  bool operator==(const VoxelIndex&) const = default;
};
struct VoxelIndexHash {
  size_t operator()(const VoxelIndex& v) const {
    return (static_cast<size_t>(static_cast<std::uint32_t>(v.x)) * 73856093u) ^
           (static_cast<size_t>(static_cast<std::uint32_t>(v.y)) * 19349663u) ^
           (static_cast<size_t>(static_cast<std::uint32_t>(v.z)) * 83492791u);
  }
};
using VoxelSet = std::unordered_set<VoxelIndex, VoxelIndexHash>;

// The true occupancy of a synthetic sequence (`pspslam synth --occupancy-truth RES`), what an
// occupancy map of it is scored against:
//   static_cells: cells the static geometry passes through (centre within half a cell diagonal
//     of the room's walls, floor and ceiling, or of the furniture, solid): the room's true
//     occupancy;
//   seen_cells: the static cells that some frame's camera saw within `max_range_m` (cells holding
//     a point of the exact depth on a static pixel, every `frame_step`-th frame): what a map of
//     the sequence can recall;
//   swept_cells: cells whose centre some person (body parts and carried box) covered at some
//     frame: where a map keeps ghosts.
// The camera's exact poses (colour instants) place an estimated map in this frame.
struct OccupancyTruth {
  double resolution = 0.05;
  double max_range_m = 4.0;
  VoxelSet static_cells, seen_cells, swept_cells;
  Trajectory camera_poses;  // T_world_camera per frame

  VoxelIndex cell_of(const Eigen::Vector3d& point) const;
  // Whether the cell or one of its 26 neighbours is static (a tolerance of one cell).
  bool static_near(const VoxelIndex& cell) const;
  Eigen::Vector3d centre_of(const VoxelIndex& cell) const;
};

struct OccupancyTruthOptions {
  double resolution = 0.05;  // > 0
  double max_range_m = 4.0;  // the synthetic camera's depth threshold
  size_t frame_step = 2;     // every n-th frame rendered for the seen cells
  int threads = 0;           // rendering threads; 0 = all cores
};

OccupancyTruth compute_occupancy_truth(const SyntheticScene& scene,
                                       const OccupancyTruthOptions& options);

// The folder `dir` (created): static.txt, seen.txt, swept.txt (one "i j k" per line after a
// header naming the resolution), camera.txt (TUM). Throws pspslam::Error naming the file.
void write_occupancy_truth(const OccupancyTruth& truth, const std::filesystem::path& dir);
// Reads what write_occupancy_truth wrote; throws pspslam::Error naming file:line.
OccupancyTruth read_occupancy_truth(const std::filesystem::path& dir);

}  // namespace pspslam
