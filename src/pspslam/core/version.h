#pragma once

#include <string>

namespace pspslam {

// "pspslam 0.1.0 (git a88f8b6)": the project version and the revision it was built from (from
// `git describe` when CMake configured the build; "unknown" outside a git checkout).
std::string version_string();

}  // namespace pspslam
