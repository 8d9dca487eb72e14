// The loaders' child processes (Assimp, OpenVDB): libraries not hardened against hostile files
// read in a forked child, so that a crash, a hang or a runaway allocation costs only the child.
#pragma once

#include <cstdint>

namespace sv::formats::detail {

// Makes the forked child behave as a fresh process would: the parent's signal handlers (a host's
// crash reporter, libFuzzer's and the sanitizers') must not run here and report the parent's
// input as theirs, so a crash ends the child by its signal; no output but the pipe `out` (standard
// output and error go to /dev/null), and no other file of the parent's held open (another load's
// pipe would not see its end while this child lives); at most `budget` more bytes of address space
// than it starts with (never above a limit already set). Returns the pipe's descriptor (moved
// above 2 if the parent had closed its standard ones).
int isolateChild(int out, uint64_t budget);

}  // namespace sv::formats::detail
