#include "core/check.h"

#include <cstdio>
#include <cstdlib>

namespace sv::core {

void checkFailed(const char* file, int line, const char* condition, const std::string& detail) {
  if (detail.empty())
    fmt::print(stderr, "{}:{}: check failed: {}\n", file, line, condition);
  else
    fmt::print(stderr, "{}:{}: check failed: {} ({})\n", file, line, condition, detail);
  std::fflush(stderr);
  std::abort();
}

}  // namespace sv::core
