#pragma once

#include <chrono>

namespace pspslam {

// Wall time since `start` in milliseconds, the unit every timing report of the project uses.
inline double milliseconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace pspslam
