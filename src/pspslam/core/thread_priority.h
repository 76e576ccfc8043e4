#pragma once

namespace pspslam {

// Lowers the scheduling priority of the calling thread only (Linux: the nice value of this thread's
// id; other threads of the process keep theirs). Real-time runs use it so that the network, local
// mapping and loop closing yield a core to the caller thread, which must track each frame before
// the next arrives. `increment` <= 0 changes nothing. Returns false when the system refused (then
// the thread runs on at its old priority).
bool lower_this_thread_priority(int increment);

// The calling thread's nice value (for tests and the run report).
int this_thread_nice();

// Raises the calling thread's scheduling priority to the nice value `nice` (< 0: above normal
// programs) for the object's lifetime; threads it starts meanwhile inherit it, and threads that
// lower theirs (lower_this_thread_priority) do so from it. Live runs use it so that tracking keeps
// up with the camera beside busy programs of normal priority. It needs root, CAP_SYS_NICE or an
// RLIMIT_NICE that allows it; when the system refuses, nothing changes and raised() is false.
// A nice value at or above the thread's own changes nothing.
class ScopedThreadPriority {
 public:
  explicit ScopedThreadPriority(int nice);
  ~ScopedThreadPriority();
  ScopedThreadPriority(const ScopedThreadPriority&) = delete;
  ScopedThreadPriority& operator=(const ScopedThreadPriority&) = delete;

  bool raised() const { return raised_; }
  int wanted() const { return wanted_; }

 private:
  int previous_;
  int wanted_;
  bool raised_ = false;
};

// Keeps BLAS/LAPACK calls on the calling thread. OpenCV and Ceres link the system BLAS, which on
// Debian is OpenBLAS's pthread build: its workers spin on sched_yield after each call, and the
// calls here are small (a few dozen rows), so on two cores the spinning takes a large share of a
// core from tracking, local mapping and the network, as system time. Found at run time (dlsym), so
// a BLAS without threads or without OpenBLAS's entry point is left as it is. Returns true when
// OpenBLAS was told.
bool use_single_threaded_blas();

// OpenBLAS's thread count, or 0 when the BLAS in use is not OpenBLAS (for the run report).
int blas_threads();

}  // namespace pspslam
