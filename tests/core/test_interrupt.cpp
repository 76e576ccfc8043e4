#include <gtest/gtest.h>

#include <csignal>

#include "pspslam/core/interrupt.h"

namespace pspslam {
namespace {

void (*current_handler(int signal_number))(int) {
  struct sigaction action {};
  sigaction(signal_number, nullptr, &action);
  return action.sa_handler;
}

void marker_handler(int) {}

TEST(InterruptGuard, SignalSetsFlagInsteadOfTerminating) {
  clear_interrupt();
  {
    InterruptGuard guard;
    EXPECT_FALSE(interrupted());
    std::raise(SIGTERM);
    EXPECT_TRUE(interrupted());
    EXPECT_EQ(interrupt_signal(), SIGTERM);
  }
  clear_interrupt();
  EXPECT_FALSE(interrupted());
  EXPECT_EQ(interrupt_signal(), 0);
}

TEST(InterruptGuard, RestoresPreviousHandlers) {
  std::signal(SIGINT, marker_handler);
  std::signal(SIGTERM, marker_handler);
  {
    InterruptGuard guard;
    EXPECT_NE(current_handler(SIGINT), &marker_handler);
    EXPECT_NE(current_handler(SIGTERM), &marker_handler);
  }
  EXPECT_EQ(current_handler(SIGINT), &marker_handler);
  EXPECT_EQ(current_handler(SIGTERM), &marker_handler);
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
}

TEST(InterruptGuard, NestedGuardsRestoreInOrder) {
  clear_interrupt();
  InterruptGuard outer;
  const auto outer_handler = current_handler(SIGINT);
  {
    InterruptGuard inner;
    std::raise(SIGINT);
  }
  EXPECT_EQ(current_handler(SIGINT), outer_handler);
  EXPECT_TRUE(interrupted()) << "the inner guard must not swallow the signal";
  clear_interrupt();
}

TEST(InterruptGuardDeathTest, SecondSignalTerminates) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(
      {
        InterruptGuard guard;
        std::raise(SIGINT);
        std::raise(SIGINT);
        std::exit(0);  // not reached: the second SIGINT takes the default action
      },
      ::testing::KilledBySignal(SIGINT), "");
}

}  // namespace
}  // namespace pspslam
