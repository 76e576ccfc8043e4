#pragma once

#include <ctime>

namespace pspslam {

// CPU time the calling thread has used, in milliseconds. Beside wall time it tells what a stage
// costs itself; on a loaded machine wall time also counts waiting for a core.
inline double thread_cpu_ms() {
  timespec now{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return 1e3 * static_cast<double>(now.tv_sec) + 1e-6 * static_cast<double>(now.tv_nsec);
}

}  // namespace pspslam
