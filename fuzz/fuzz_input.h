#pragma once

// Shared by the fuzz targets: every reader under test takes a path, so each input is written to
// a scratch file first. One folder per process, removed when the process ends.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <string_view>

#include "pspslam/core/error.h"

namespace pspslam::fuzz {

class ScratchFolder {
 public:
  ScratchFolder()
      : path_(std::filesystem::temp_directory_path() /
              ("pspslam_fuzz_" + std::to_string(::getpid()))) {
    std::filesystem::create_directories(path_);
  }
  ~ScratchFolder() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  ScratchFolder(const ScratchFolder&) = delete;
  ScratchFolder& operator=(const ScratchFolder&) = delete;

  // Writes `bytes` to NAME inside the folder and returns its path.
  std::filesystem::path write(const std::string& name, std::string_view bytes) const {
    const std::filesystem::path file = path_ / name;
    std::ofstream(file, std::ios::binary | std::ios::trunc)
        .write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return file;
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

inline const ScratchFolder& scratch() {
  static const ScratchFolder folder;  // one per fuzzing process
  return folder;
}

inline std::string_view as_text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

// Runs a reader on one input. A pspslam::Error is the reader refusing bad input properly; any
// other exception escapes, and libFuzzer reports it as a crash (the CLI would print "internal
// error" and exit 3 on it).
template <typename Reader>
void expect_clean(Reader&& reader) {
  // PSPSLAM_FUZZ_VERBOSE=1 prints each refusal, to check that seeds reach the deep checks.
  static const bool verbose = std::getenv("PSPSLAM_FUZZ_VERBOSE") != nullptr;
  try {
    reader();
    if (verbose) std::cerr << "accepted\n";
  } catch (const pspslam::Error& e) {
    if (verbose) std::cerr << "refused: " << e.what() << "\n";
  }
}

}  // namespace pspslam::fuzz
