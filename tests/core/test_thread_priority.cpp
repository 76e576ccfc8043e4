#include <gtest/gtest.h>

#include <unistd.h>

#include <thread>

#include "pspslam/core/thread_priority.h"

namespace pspslam {
namespace {

TEST(ThreadPriority, LowersOnlyTheCallingThread) {
  const int caller_before = this_thread_nice();
  int worker_before = 0;
  int worker_after = 0;
  bool lowered = false;
  std::thread worker([&] {
    worker_before = this_thread_nice();
    lowered = lower_this_thread_priority(3);
    worker_after = this_thread_nice();
  });
  worker.join();
  EXPECT_TRUE(lowered);
  EXPECT_EQ(worker_before, caller_before);  // a new thread starts at its creator's priority
  EXPECT_EQ(worker_after, std::min(19, caller_before + 3));
  EXPECT_EQ(this_thread_nice(), caller_before);
}

TEST(ThreadPriority, ZeroOrNegativeIncrementChangesNothing) {
  std::thread worker([] {
    const int before = this_thread_nice();
    EXPECT_TRUE(lower_this_thread_priority(0));
    EXPECT_TRUE(lower_this_thread_priority(-5));
    EXPECT_EQ(this_thread_nice(), before);
  });
  worker.join();
}

// Raising a priority is a privilege (root, CAP_SYS_NICE or RLIMIT_NICE): granted, the thread and
// the threads it starts run at the raised value until the guard ends; refused, nothing changes.
TEST(ThreadPriority, ARaisedPriorityIsInheritedAndUndoneOrRefusedCleanly) {
  std::thread worker([] {
    const int before = this_thread_nice();
    int child_nice = 0;
    bool raised = false;
    {
      const ScopedThreadPriority priority(before - 5);
      raised = priority.raised();
      std::thread child([&] { child_nice = this_thread_nice(); });
      child.join();
      EXPECT_EQ(this_thread_nice(), raised ? before - 5 : before);
      EXPECT_EQ(child_nice, this_thread_nice());
    }
    EXPECT_EQ(this_thread_nice(), before);
    if (geteuid() == 0) {
      EXPECT_TRUE(raised);  // root may always raise
    }
  });
  worker.join();
}

TEST(ThreadPriority, ANiceValueNotAboveTheThreadsOwnChangesNothing) {
  std::thread worker([] {
    const int before = this_thread_nice();
    const ScopedThreadPriority same(before);
    EXPECT_FALSE(same.raised());
    EXPECT_EQ(this_thread_nice(), before);
  });
  worker.join();
}

// Debian's BLAS is OpenBLAS (pthreads), linked through OpenCV: told to, it runs on one thread;
// another BLAS has no thread count to report.
TEST(ThreadPriority, BlasRunsOnTheCallingThread) {
  const bool openblas = use_single_threaded_blas();
  EXPECT_EQ(blas_threads(), openblas ? 1 : 0);
}

}  // namespace
}  // namespace pspslam
