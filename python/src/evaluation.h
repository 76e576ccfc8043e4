#pragma once

#include <pybind11/pybind11.h>

#include <string>

#include "pspslam/core/types.h"

namespace pspslam::python {

namespace py = pybind11;

// A trajectory from Python: either (timestamps N, poses Nx4x4 camera-to-world), what the module
// returns, or an Nx8 array of TUM rows `t tx ty tz qx qy qz qw` (numpy.loadtxt of a TUM file),
// whose quaternions are checked and normalised as read_tum_trajectory does. `argument` names it
// in errors.
Trajectory trajectory_from(const py::handle& object, const std::string& argument);

// pspslam.ate / pspslam.rpe / write_trajectory / read_trajectory (module.cpp registers them).
void register_evaluation(py::module_& module);

}  // namespace pspslam::python
