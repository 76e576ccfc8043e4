#pragma once

#include <filesystem>

namespace pspslam {

// Where the read-only ../shared folder (datasets, teacher models) is: $PSPSLAM_SHARED when set,
// otherwise "../shared" next to the source checkout. Never a hard-coded absolute path.
std::filesystem::path shared_dir();

// The repository root (tests and tools that read repository files).
std::filesystem::path source_dir();

// The folder that holds the shipped data (models/, config/): DATA/share/pspslam next to an
// installed program (bin/../share/pspslam, found from the running executable, so an installed
// tree may be moved anywhere), or PREFIX/share/pspslam above the installed Python extension
// that holds this code, else the source tree of a build that was not installed.
std::filesystem::path data_dir();

}  // namespace pspslam
