// A command through the shell, as a user types it: its output (standard output and error
// together) and its exit status — for the tests of the command-line tool.
#pragma once

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace sv::tests {

struct ShellRun {
  int status = -1;  // the exit status, or 128 + the signal that ended it
  std::string out;  // stdout and stderr together
};

inline ShellRun shell(const std::string& command) {
  ShellRun r;
  FILE* p = popen((command + " 2>&1").c_str(), "r");
  if (!p) return r;
  std::array<char, 4096> buf;
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) r.out.append(buf.data(), n);
  const int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
  return r;
}

}  // namespace sv::tests
