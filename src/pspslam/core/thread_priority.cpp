#include "pspslam/core/thread_priority.h"

#include <dlfcn.h>
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

ScopedThreadPriority::ScopedThreadPriority(int nice)
    : previous_(this_thread_nice()), wanted_(nice) {
  if (nice >= previous_) return;
  raised_ = setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), nice) == 0;
}

ScopedThreadPriority::~ScopedThreadPriority() {
  // Going back down is always allowed.
  if (raised_) setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), previous_);
}

bool use_single_threaded_blas() {
  using SetThreads = void (*)(int);
  void* const symbol = dlsym(RTLD_DEFAULT, "openblas_set_num_threads");
  if (symbol == nullptr) return false;
  reinterpret_cast<SetThreads>(symbol)(1);
  return true;
}

int blas_threads() {
  using GetThreads = int (*)();
  void* const symbol = dlsym(RTLD_DEFAULT, "openblas_get_num_threads");
  return symbol == nullptr ? 0 : reinterpret_cast<GetThreads>(symbol)();
}

}  // namespace pspslam
