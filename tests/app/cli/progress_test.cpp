// InterruptGuard (app/cli/Progress.h): the first SIGINT raises the flag the simulation polls, the second ends
// the process at once (issue 15, class 10; docs/cli.md).
#include "Progress.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

using pneuma::app::InterruptGuard;

TEST(InterruptGuard, FirstSigintRaisesTheFlagSecondEndsTheProcess) {
  const pid_t pid = fork();
  if (pid == 0) {
    InterruptGuard guard;
    if (InterruptGuard::isInterrupted() || InterruptGuard::flag()->load()) _exit(2);
    raise(SIGINT);
    if (!InterruptGuard::isInterrupted() || !InterruptGuard::flag()->load()) _exit(3);
    raise(SIGINT);  // must not return
    _exit(4);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the child exited with " << WEXITSTATUS(status)
                                   << " (2: flag up before, 3: first SIGINT lost, 4: survived the second)";
  EXPECT_EQ(WTERMSIG(status), SIGINT);
}

TEST(InterruptGuard, RestoresThePreviousHandler) {
  struct sigaction before {};
  sigaction(SIGINT, nullptr, &before);
  { InterruptGuard guard; }
  struct sigaction after {};
  sigaction(SIGINT, nullptr, &after);
  EXPECT_EQ(before.sa_handler, after.sa_handler);
}
