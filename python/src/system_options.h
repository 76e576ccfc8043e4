#pragma once

#include "pspslam/session/run_settings.h"
#include "pspslam/system/system.h"

namespace pspslam::python {

// The SystemOptions `pspslam run` makes from the same settings (session/run_settings.h):
// deterministic unless `realtime` or `live` (frames from a live source as they arrive, as
// `run --camera`). Each keyword's value was checked as it was read (run_option_table.h); raises
// ValueError for settings that do not go together, pspslam.Error for a model that does not load.
SystemOptions checked_system_options(const RunSettings& settings);

}  // namespace pspslam::python
