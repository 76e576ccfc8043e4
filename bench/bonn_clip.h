#pragma once

// The colour frames of ../shared/data/bonn_crowd_dev for the benchmarks that time real images.

#include <algorithm>
#include <filesystem>
#include <vector>

#include "pspslam/core/shared_paths.h"

namespace pspslam::bench {

// The clip's JPEG files in time order (their names are timestamps); empty without ../shared.
inline std::vector<std::filesystem::path> bonn_rgb_files() {
  const std::filesystem::path folder = shared_dir() / "data" / "bonn_crowd_dev" / "rgb";
  std::vector<std::filesystem::path> files;
  if (std::filesystem::is_directory(folder)) {
    for (const auto& entry : std::filesystem::directory_iterator(folder)) {
      if (entry.path().extension() == ".jpg") files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace pspslam::bench
