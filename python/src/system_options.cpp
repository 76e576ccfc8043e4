#include "system_options.h"

#include <pybind11/pybind11.h>

#include <string>

#include "pspslam/core/error.h"
#include "pspslam/session/run_option_table.h"

namespace pspslam::python {

namespace py = pybind11;

SystemOptions checked_system_options(const RunSettings& settings) {
  // The keywords' names; a model that does not load is raised as its own error.
  const SettingNames names{
      .mode = "mode", .semantic_masks = "semantic_masks", .explain_model = false, .keywords = true};
  try {
    check_run_settings(settings, names);
  } catch (const Error& e) {
    throw py::value_error(e.what());
  }
  if (settings.semantic_masks && settings.mode != "auto" &&
      !uses_semantics(parse_dynamic_mode(settings.mode, "mode")))
    throw py::value_error("semantic_masks: replaces the network's masks, but mode " +
                          settings.mode + " uses none (use semantic, full or exhaustive)");
  return system_options(settings, names);
}

}  // namespace pspslam::python
