#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <utility>

#include "pspslam/system/system.h"

namespace pspslam::python {

// The `pspslam run` flags that shape the System, by the same names (Python keywords use `_` for
// `-`), with the same defaults and ranges. Empty optionals take the CLI's default.
struct RunSettings {
  std::string mode = "full";  // --dynamic: off | semantic | geometry | full | exhaustive | auto
  std::optional<std::filesystem::path> model;       // --model
  std::optional<std::filesystem::path> vocabulary;  // --vocabulary
  std::optional<std::filesystem::path> semantic_masks;
  std::optional<std::filesystem::path> load_map;  // --load-map
  bool localization = false;
  bool realtime = false;
  bool local_mapping = true;  // --no-local-mapping turns it off
  bool relocalization = true;
  std::string loop_closing = "auto";  // on | off | auto
  int mask_margin = 5;
  int segment_every = 1;
  int cull_hits = 3;
  double keyframe_ratio = KeyFramePolicyOptions{}.tracked_ratio_to_reference;
  bool due_keyframes = false;
  std::optional<int> local_ba_keyframes;
  std::optional<int> background_nice;
  std::optional<std::pair<double, double>> motion_prior;  // millimetres, degrees
};

// The SystemOptions `pspslam run` makes from the same flags for a recorded sequence (a camera's
// back-end wait is not here: Python feeds recorded or own frames). Deterministic unless
// `realtime`: each frame waits for its mask and the whole back end. Raises ValueError naming the
// keyword for a value the CLI would refuse, pspslam.Error for a model that does not load.
SystemOptions system_options(const RunSettings& settings);

}  // namespace pspslam::python
