#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "pspslam/core/types.h"
#include "pspslam/occupancy/occupancy_map.h"
#include "pspslam/occupancy/occupancy_options.h"

namespace pspslam {

// The floor: the points p of the world with up . p = height.
struct FloorPlane {
  Eigen::Vector3d up = -Eigen::Vector3d::UnitY();  // the first camera's -y
  double height = 0.0;
  bool from_map = false;  // found in the map (else taken from the options or a fallback)
  size_t support = 0;     // occupied voxels on the plane
};

// The floor as GridOptions says: its height along the first camera's -y, or found in the map:
// the level plane (within 30 degrees of -y) below the median camera that holds the most
// occupied voxels (RANSAC with a fixed seed, then least squares). Without one, the lowest
// percent of the occupied voxels.
FloorPlane find_floor(const OccupancyMap& map, const std::vector<Eigen::Vector3d>& camera_centres,
                      const GridOptions& options);

inline constexpr std::int8_t kGridUnknown = -1;
inline constexpr std::int8_t kGridFree = 0;
inline constexpr std::int8_t kGridOccupied = 100;

// A 2D occupancy grid as ROS navigation reads it: cells of `resolution` on the floor, row 0 at
// the lowest y; a cell is occupied when an occupied voxel lies over it within the height band,
// free when only free voxels do, unknown otherwise.
struct OccupancyGrid {
  double resolution = 0.05;
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();  // the corner of cell (0, 0), grid frame
  int width = 0, height = 0;
  std::vector<std::int8_t> cells;  // row-major, kGrid* values
  // The grid frame in the SLAM world: x and y on the floor, z up, origin on the floor.
  Pose T_world_grid = Pose::Identity();
  FloorPlane floor;

  std::int8_t at(int column, int row) const {
    return cells[static_cast<size_t>(row) * width + column];
  }
  size_t count(std::int8_t state) const;
  // The cell under a world point, or false when it is outside the grid.
  bool cell_of(const Eigen::Vector3d& world_point, int& column, int& row) const;
};

OccupancyGrid make_grid(const OccupancyMap& map, const FloorPlane& floor,
                        const GridOptions& options);

// map_server's format: `yaml` (image, resolution, origin, negate, occupied_thresh, free_thresh,
// mode) and the PGM beside it (same name, .pgm): occupied 0, free 254, unknown 205, the top row
// the highest y. Throws pspslam::Error naming the file.
void write_map_server(const OccupancyGrid& grid, const std::filesystem::path& yaml);

}  // namespace pspslam
