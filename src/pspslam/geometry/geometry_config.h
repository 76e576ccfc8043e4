#pragma once

#include "pspslam/config/config.h"
#include "pspslam/geometry/geometry_stage.h"

namespace pspslam {

// The `geometry:` section of a config (GeometryParams::from_yaml), as a run may set it. Which
// search runs is not a key: `pspslam run --dynamic` chooses it (full: the reverse ant colony,
// exhaustive: every point), so `search.strategy` is refused, as is `output_warped_previous_mask`
// (an output a run never reads). Errors name the file, the line and the key.
GeometryParams read_geometry_config(const ConfigSection& section);

}  // namespace pspslam
