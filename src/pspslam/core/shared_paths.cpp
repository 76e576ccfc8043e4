#include "pspslam/core/shared_paths.h"

#include <cstdlib>

namespace pspslam {

std::filesystem::path source_dir() { return std::filesystem::path(PSPSLAM_SOURCE_DIR); }

std::filesystem::path shared_dir() {
  if (const char* env = std::getenv("PSPSLAM_SHARED"); env != nullptr && *env != '\0') {
    return std::filesystem::path(env);
  }
  return source_dir().parent_path() / "shared";
}

}  // namespace pspslam
