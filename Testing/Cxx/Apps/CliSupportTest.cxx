// CliSupport: the Ctrl-C guard sets the cancel flag while alive and restores the previous SIGINT handler on every
// path out of its scope.
#include <gtest/gtest.h>

#include <csignal>

#include "CliSupport.h"

namespace {

volatile std::sig_atomic_t g_previousCalls = 0;
extern "C" void countingHandler(int) { g_previousCalls = g_previousCalls + 1; }

/// Leaves through an early return, as a failing command does.
int failEarly(bool fail) {
  const fct::cli::InterruptGuard interrupt;
  if (fail) return 2;
  return 0;
}

}  // namespace

TEST(InterruptGuard, CtrlCSetsTheCancelFlagInsteadOfTheHandlerBefore) {
  const auto before = std::signal(SIGINT, countingHandler);
  g_previousCalls = 0;
  {
    const fct::cli::InterruptGuard interrupt;
    EXPECT_FALSE(fct::cli::InterruptGuard::cancelFlag()->load());
    std::raise(SIGINT);
    EXPECT_TRUE(fct::cli::InterruptGuard::cancelFlag()->load());
    EXPECT_EQ(g_previousCalls, 0);
  }
  std::raise(SIGINT);
  EXPECT_EQ(g_previousCalls, 1) << "the previous handler is back";
  std::signal(SIGINT, before);
}

TEST(InterruptGuard, RestoresThePreviousHandlerAfterAnEarlyReturn) {
  const auto before = std::signal(SIGINT, countingHandler);
  EXPECT_EQ(failEarly(true), 2);
  EXPECT_EQ(std::signal(SIGINT, countingHandler), &countingHandler);
  EXPECT_EQ(failEarly(false), 0);
  EXPECT_EQ(std::signal(SIGINT, before), &countingHandler);
}

TEST(InterruptGuard, ANewGuardStartsWithTheFlagCleared) {
  const auto before = std::signal(SIGINT, countingHandler);
  {
    const fct::cli::InterruptGuard first;
    std::raise(SIGINT);
  }
  const fct::cli::InterruptGuard second;
  EXPECT_FALSE(fct::cli::InterruptGuard::cancelFlag()->load());
  std::signal(SIGINT, before);
}
