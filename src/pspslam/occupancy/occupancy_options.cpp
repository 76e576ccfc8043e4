#include "pspslam/occupancy/occupancy_options.h"

#include <cmath>
#include <string>

#include "pspslam/core/error.h"

namespace pspslam {

void OccupancyOptions::validate() const {
  if (!(resolution_m > 0.0) || !std::isfinite(resolution_m))
    throw Error("flag --occupancy-resolution: must be > 0 metres, got " +
                std::to_string(resolution_m));
  if (!(max_range_m > resolution_m))
    throw Error("flag --occupancy-max-range: must exceed --occupancy-resolution, got " +
                std::to_string(max_range_m) + " m");
  if (pixel_stride < 1) throw Error("occupancy: the pixel stride must be >= 1");
  if (insert_delay_keyframes < 0) throw Error("occupancy: the insertion delay must be >= 0");
}

void GridOptions::validate() const {
  if (!std::isfinite(min_height_m) || !std::isfinite(max_height_m))
    throw Error("flags --grid-min-height / --grid-max-height: must be finite");
  if (!(max_height_m > min_height_m))
    throw Error("flags --grid-min-height " + std::to_string(min_height_m) +
                " and --grid-max-height " + std::to_string(max_height_m) +
                ": the height band is upside down (max must be above min)");
  if (floor_height_m && !std::isfinite(*floor_height_m))
    throw Error("flag --grid-floor: must be a finite height in metres or 'auto'");
}

}  // namespace pspslam
