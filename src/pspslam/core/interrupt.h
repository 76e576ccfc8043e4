#pragma once

#include <csignal>

namespace pspslam {

// Lets long loops (sequence loading, SLAM runs) stop cleanly on Ctrl-C / `kill`: while an
// InterruptGuard lives, SIGINT and SIGTERM only raise a flag that the loop polls with
// interrupted(), so the loop can flush its output (the trajectory written so far) and return.
// A second signal while the flag is already set terminates the process the default way, so a
// stuck program can still be killed with a second Ctrl-C.
//
// The destructor restores the handlers that were installed before, so guards may be nested
// (the inner one restores the outer one's handlers). Not thread-safe to construct concurrently;
// construct it on the main thread, poll interrupted() from any thread.
class InterruptGuard {
 public:
  InterruptGuard();
  ~InterruptGuard();
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;

 private:
  struct sigaction previous_interrupt_ {};
  struct sigaction previous_terminate_ {};
};

// True once SIGINT or SIGTERM arrived while an InterruptGuard was alive.
bool interrupted();

// The signal that set the flag (SIGINT or SIGTERM), 0 when none did.
int interrupt_signal();

// Clears the flag (e.g. between two runs in one process, and in tests). A guard does not clear
// it on construction, so a nested guard cannot swallow a signal meant for an outer loop.
void clear_interrupt();

}  // namespace pspslam
