#include "pspslam/core/shared_paths.h"

#include <dlfcn.h>

#include <cstdlib>
#include <system_error>

namespace pspslam {
namespace {

// PREFIX/share/pspslam when it holds the models.
bool holds_installed_data(const std::filesystem::path& prefix) {
  std::error_code ec;
  return std::filesystem::is_directory(prefix / "share" / "pspslam" / "models", ec);
}

// The shared object this code was loaded from when it is not the program: the Python extension
// (PREFIX/lib/python3/dist-packages/pspslam/_pspslam*.so), whose program is the interpreter.
std::filesystem::path loading_shared_object() {
  Dl_info info{};
  if (dladdr(reinterpret_cast<const void*>(&data_dir), &info) == 0 || info.dli_fname == nullptr)
    return {};
  const std::filesystem::path file = info.dli_fname;
  return file.extension() == ".so" ? file : std::filesystem::path();
}

}  // namespace

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
    const std::filesystem::path prefix = executable.parent_path().parent_path();
    if (holds_installed_data(prefix)) return prefix / "share" / "pspslam";
  }
  // The extension lies some folders below PREFIX (lib/python3/dist-packages/pspslam, or
  // lib/python3.11/site-packages/pspslam): the nearest folder above it with the data.
  const std::filesystem::path extension = loading_shared_object();
  for (std::filesystem::path folder = extension.parent_path(); folder.has_relative_path();
       folder = folder.parent_path()) {
    if (holds_installed_data(folder)) return folder / "share" / "pspslam";
  }
  return source_dir();
}

}  // namespace pspslam
