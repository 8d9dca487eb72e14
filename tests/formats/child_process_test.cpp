// The loaders' child isolation (src/scene/child_process.h): what a forked child keeps of its
// parent after isolateChild — no handlers of the listed signals, no other open files, no output but
// its pipe, and a bounded address space.
#include "formats/child_process.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include <string>

namespace sv::formats::detail {
namespace {

void onTerm(int) {}

TEST(ChildProcess, IsolationDropsHandlersFilesAndOutputAndBoundsMemory) {
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  const int other = open("/dev/null", O_RDONLY);  // a file of the parent's, open at the fork
  ASSERT_GE(other, 0);
  struct sigaction handler {};
  struct sigaction previous {};
  handler.sa_handler = onTerm;
  ASSERT_EQ(sigaction(SIGTERM, &handler, &previous), 0);
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    close(fds[0]);
    const int out = isolateChild(fds[1], uint64_t(256) << 20);
    std::string report;
    struct sigaction now {};
    sigaction(SIGTERM, nullptr, &now);
    report += now.sa_handler == SIG_DFL ? 'd' : 'h';          // the handler reset
    report += fcntl(other, F_GETFD) < 0 ? 'c' : 'o';          // the parent's file closed
    report += write(STDOUT_FILENO, "x", 1) == 1 ? 'w' : 'f';  // output still writable…
    // Mapped, not malloc'ed: under AddressSanitizer a failed malloc ends the process.
    const auto map = [](size_t bytes) {
      return mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    };
    report += map(size_t(1) << 30) == MAP_FAILED ? 'r' : 'a';   // … but 1 GiB is refused
    report += map(size_t(16) << 20) != MAP_FAILED ? 's' : 'n';  // within the budget
    if (write(out, report.data(), report.size()) != ssize_t(report.size())) _exit(2);
    _exit(0);
  }
  close(fds[1]);
  sigaction(SIGTERM, &previous, nullptr);
  char buffer[16] = {};
  const ssize_t n = read(fds[0], buffer, sizeof buffer);
  close(fds[0]);
  close(other);
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;
  EXPECT_EQ(std::string(buffer, size_t(std::max<ssize_t>(n, 0))), "dcwrs");
}

}  // namespace
}  // namespace sv::formats::detail
