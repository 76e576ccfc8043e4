#include "pspslam/core/thread_priority.h"

#include <sys/resource.h>
#include <unistd.h>

#include <cerrno>

namespace pspslam {

int this_thread_nice() {
  errno = 0;  // getpriority may legitimately return -1
  return getpriority(PRIO_PROCESS, static_cast<id_t>(gettid()));
}

bool lower_this_thread_priority(int increment) {
  if (increment <= 0) return true;
  // With a thread id, PRIO_PROCESS addresses that thread alone (Linux's per-thread nice).
  return setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), this_thread_nice() + increment) ==
         0;
}

}  // namespace pspslam
