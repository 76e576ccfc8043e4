#include "system_options.h"

#include <pybind11/pybind11.h>

#include <initializer_list>
#include <string>

namespace pspslam::python {
namespace {

namespace py = pybind11;

// A number as Python prints it (1e-3 as 0.001, 100 as 100).
template <typename T>
std::string python_text(T value) {
  return py::str(py::cast(value));
}

template <typename T>
void require_range(T value, T low, T high, const char* keyword) {
  if (!(value >= low && value <= high)) {
    throw py::value_error(std::string(keyword) + ": expected a value in [" + python_text(low) +
                          ", " + python_text(high) + "], got " + python_text(value));
  }
}

void require_member(const std::string& value, std::initializer_list<const char*> allowed,
                    const char* keyword) {
  std::string listed;
  for (const char* name : allowed) {
    if (value == name) return;
    if (!listed.empty()) listed += " | ";
    listed += name;
  }
  throw py::value_error(std::string(keyword) + ": expected " + listed + ", got '" + value + "'");
}

void check_ranges(const RunSettings& settings) {
  require_member(settings.mode, {"off", "semantic", "geometry", "full", "exhaustive", "auto"},
                 "mode");
  require_member(settings.loop_closing, {"on", "off", "auto"}, "loop_closing");
  require_range(settings.mask_margin, 0, 100, "mask_margin");
  require_range(settings.segment_every, 1, 30, "segment_every");
  require_range(settings.cull_hits, 1, 1000, "cull_hits");
  require_range(settings.keyframe_ratio, 0.01, 1.0, "keyframe_ratio");
  if (settings.new_map_after) require_range(*settings.new_map_after, 0.0, 3600.0, "new_map_after");
  if (settings.local_ba_keyframes)
    require_range(*settings.local_ba_keyframes, 0, 1000, "local_ba_keyframes");
  if (settings.background_nice) require_range(*settings.background_nice, 0, 19, "background_nice");
  if (settings.motion_prior) {
    require_range(settings.motion_prior->first, 1e-3, 1e3, "motion_prior");
    require_range(settings.motion_prior->second, 1e-3, 1e3, "motion_prior");
  }
  if (settings.localization && !settings.load_map)
    throw py::value_error("localization: needs load_map (a map to localise in)");
  if (settings.semantic_masks && settings.mode != "auto" &&
      !uses_semantics(parse_dynamic_mode(settings.mode, "mode")))
    throw py::value_error("semantic_masks: replaces the network's masks, but mode " +
                          settings.mode + " uses none (use semantic, full or exhaustive)");
}

}  // namespace

SystemOptions checked_system_options(const RunSettings& settings) {
  check_ranges(settings);
  // The keywords' names; a model that does not load is raised as its own error.
  const SettingNames names{
      .mode = "mode", .semantic_masks = "semantic_masks", .explain_model = false};
  return system_options(settings, names);
}

}  // namespace pspslam::python
