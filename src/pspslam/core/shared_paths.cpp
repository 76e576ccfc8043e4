#include "pspslam/core/shared_paths.h"

#include <cstdlib>
#include <system_error>

namespace pspslam {

std::filesystem::path source_dir() { return std::filesystem::path(PSPSLAM_SOURCE_DIR); }

std::filesystem::path shared_dir() {
  if (const char* env = std::getenv("PSPSLAM_SHARED"); env != nullptr && *env != '\0') {
    return std::filesystem::path(env);
  }
  return source_dir().parent_path() / "shared";
}

std::filesystem::path data_dir() {
  std::error_code ec;
  const std::filesystem::path executable = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const std::filesystem::path installed =
        executable.parent_path().parent_path() / "share" / "pspslam";
    if (std::filesystem::is_directory(installed / "models", ec)) return installed;
  }
  return source_dir();
}

}  // namespace pspslam
