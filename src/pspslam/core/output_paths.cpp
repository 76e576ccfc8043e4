#include "pspslam/core/output_paths.h"

#include <fstream>
#include <system_error>

#include "pspslam/core/error.h"

namespace pspslam {

namespace fs = std::filesystem;

void prepare_output_folder(const fs::path& folder, const std::string& flag) {
  const std::string named = flag + " '" + folder.string() + "'";
  // The nearest part of the path that exists must be a folder; create_directories would
  // otherwise fail with a bare filesystem error deep inside the run.
  for (fs::path part = folder; !part.empty(); part = part.parent_path()) {
    std::error_code ec;
    const fs::file_status status = fs::status(part, ec);
    if (fs::exists(status)) {
      if (!fs::is_directory(status)) {
        throw Error(named + ": '" + part.string() + "' is a file, not a folder");
      }
      break;
    }
    if (part == part.parent_path()) break;
  }
  std::error_code ec;
  fs::create_directories(folder, ec);
  if (ec) throw Error(named + ": cannot create the folder: " + ec.message());
  // A folder we may not write into (read-only mount, other owner) fails here, not at the end.
  const fs::path probe = folder / ".pspslam_write_test";
  {
    std::ofstream stream(probe);
    if (!stream) throw Error(named + ": cannot write into the folder");
  }
  fs::remove(probe, ec);
}

void prepare_output_file(const fs::path& file, const std::string& flag) {
  if (fs::is_directory(file)) {
    throw Error(flag + " '" + file.string() + "' is a folder; give a file name");
  }
  const fs::path folder = file.parent_path();
  if (!folder.empty()) prepare_output_folder(folder, flag);
}

}  // namespace pspslam
