#pragma once

#include <filesystem>

namespace pspslam {

// Where the read-only ../shared folder (datasets, teacher models) is: $PSPSLAM_SHARED when set,
// otherwise "../shared" next to the source checkout. Never a hard-coded absolute path.
std::filesystem::path shared_dir();

// The repository root (for shipped presets and models).
std::filesystem::path source_dir();

}  // namespace pspslam
