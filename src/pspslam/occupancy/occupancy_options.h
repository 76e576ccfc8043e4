#pragma once

#include <optional>

namespace pspslam {

// How keyframes become the occupancy map of the static scene (`pspslam run --occupancy`).
struct OccupancyOptions {
  double resolution_m = 0.05;  // --occupancy-resolution: voxel edge
  double max_range_m = 4.0;    // --occupancy-max-range: farther readings mark free space only
  int pixel_stride = 4;        // every stride-th pixel in x and y of a keyframe's depth
  bool use_masks = true;       // --occupancy-masks: leave the dynamic pixels out
  bool clearing = true;        // --occupancy-clearing: rays free the cells they pass through
  // Keyframes this many keyframes old enter the map, so local BA has refined their pose.
  int insert_delay_keyframes = 5;

  // Throws pspslam::Error naming the flag of a value out of range.
  void validate() const;
};

// The 2D grid (`--export-grid`): the occupancy map over a height band above the floor.
struct GridOptions {
  double min_height_m = 0.10;  // --grid-min-height: above the floor
  double max_height_m = 1.50;  // --grid-max-height: the robot's height
  // --grid-floor: the floor's height along the world's up axis (the first camera's -y);
  // none: found from the map (the largest level plane below the cameras).
  std::optional<double> floor_height_m;

  void validate() const;
};

}  // namespace pspslam
