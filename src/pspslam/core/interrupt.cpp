#include "pspslam/core/interrupt.h"

#include <atomic>
#include <string>

#include "pspslam/core/error.h"

namespace pspslam {
namespace {

// A signal handler receives no context pointer, so the flag it sets has to live in static
// storage. It is a function-local static (not a namespace-scope global) that is
// constant-initialised: no lazy-initialisation guard runs inside the handler, and a lock-free
// atomic is one of the few things a handler may touch (async-signal-safe). It holds the signal
// number, 0 meaning "not interrupted".
std::atomic<int>& signal_flag() {
  static_assert(std::atomic<int>::is_always_lock_free,
                "the interrupt flag must be lock-free to be set from a signal handler");
  static constinit std::atomic<int> flag{0};
  return flag;
}

extern "C" void handle_interrupt(int signal_number) {
  int expected = 0;
  if (!signal_flag().compare_exchange_strong(expected, signal_number)) {
    // Second signal: the user insists. Fall back to the default action (terminate).
    std::signal(signal_number, SIG_DFL);
    std::raise(signal_number);
  }
}

void install(int signal_number, struct sigaction* previous) {
  struct sigaction action {};
  action.sa_handler = handle_interrupt;
  sigemptyset(&action.sa_mask);
  // SA_RESTART: blocking reads/writes in other code resume instead of failing with EINTR.
  action.sa_flags = SA_RESTART;
  if (sigaction(signal_number, &action, previous) != 0) {
    throw Error("cannot install the handler for signal " + std::to_string(signal_number));
  }
}

}  // namespace

InterruptGuard::InterruptGuard() {
  install(SIGINT, &previous_interrupt_);
  try {
    install(SIGTERM, &previous_terminate_);
  } catch (...) {
    sigaction(SIGINT, &previous_interrupt_, nullptr);
    throw;
  }
}

InterruptGuard::~InterruptGuard() {
  sigaction(SIGTERM, &previous_terminate_, nullptr);
  sigaction(SIGINT, &previous_interrupt_, nullptr);
}

bool interrupted() { return signal_flag().load() != 0; }

int interrupt_signal() { return signal_flag().load(); }

void clear_interrupt() { signal_flag().store(0); }

}  // namespace pspslam
