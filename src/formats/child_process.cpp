#include "formats/child_process.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cstdio>
#include <initializer_list>

#if defined(__SANITIZE_ADDRESS__)
#define SV_CHILD_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SV_CHILD_ASAN 1
#endif
#endif
#ifdef SV_CHILD_ASAN
#include <sanitizer/common_interface_defs.h>
#endif

namespace sv::formats::detail {

int isolateChild(int out, uint64_t budget) {
  for (int s : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT, SIGPIPE, SIGTERM, SIGINT, SIGALRM})
    signal(s, SIG_DFL);
#ifdef SV_CHILD_ASAN
  __sanitizer_set_death_callback(nullptr);
#endif
  if (out <= STDERR_FILENO) out = fcntl(out, F_DUPFD, STDERR_FILENO + 1);
  if (const int null = open("/dev/null", O_WRONLY); null >= 0) {
    dup2(null, STDOUT_FILENO);
    dup2(null, STDERR_FILENO);
    close(null);
  }
  if (out > 3) close_range(3, unsigned(out) - 1, 0);
  close_range(unsigned(out) + 1, ~0u, 0);
  // The address space now (first field of /proc/self/statm, in pages) plus the budget; never
  // above a limit already set.
  unsigned long long pages = 0;
  if (FILE* f = std::fopen("/proc/self/statm", "r")) {
    if (std::fscanf(f, "%llu", &pages) != 1) pages = 0;
    std::fclose(f);
  }
  rlimit limit{};
  if (pages > 0 && getrlimit(RLIMIT_AS, &limit) == 0) {
    const rlim_t want = rlim_t(pages * uint64_t(sysconf(_SC_PAGESIZE)) + budget);
    if (limit.rlim_cur == RLIM_INFINITY || want < limit.rlim_cur) {
      limit.rlim_cur = want;
      setrlimit(RLIMIT_AS, &limit);
    }
  }
  return out;
}

}  // namespace sv::formats::detail
