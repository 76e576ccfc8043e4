#pragma once

#include "pspslam/session/run_settings.h"
#include "pspslam/system/system.h"

namespace pspslam::python {

// The SystemOptions `pspslam run` makes from the same settings (session/run_settings.h), for a
// recorded sequence: Python feeds recorded or its own frames, never a live camera. Deterministic
// unless `realtime`. Raises ValueError naming the keyword for a value the CLI would refuse,
// pspslam.Error for a model that does not load.
SystemOptions checked_system_options(const RunSettings& settings);

}  // namespace pspslam::python
