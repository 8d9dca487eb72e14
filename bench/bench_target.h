// The SIMD target a kernel benchmark runs: SV_BENCH_TARGET=avx2 (or avx3, sse4, scalar) makes that
// target the only one (e.g. the AVX2 kernels on an AVX-512 machine); unset, the best there is.
// Prints the target chosen, as every figure quotes it.
#pragma once

#include <benchmark/benchmark.h>
#include <hwy/targets.h>

#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace sv::bench {

// False (after a one-line error naming `program`) when the target asked for is not available.
inline bool selectBenchTarget(const char* program) {
  if (const char* want = std::getenv("SV_BENCH_TARGET"); want && *want) {
    int64_t chosen = 0;
    for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
      std::string name = hwy::TargetName(target);
      for (char& ch : name) ch = char(std::tolower(static_cast<unsigned char>(ch)));
      if (name == want || (std::string(want) == "scalar" && (name == "emu128" || name == "scalar")))
        chosen = target;
    }
    if (!chosen) {
      std::fprintf(stderr, "%s: SIMD target '%s' is not available here\n", program, want);
      return false;
    }
    hwy::SetSupportedTargetsForTest(chosen);
  }
  std::printf("SIMD target %s\n", hwy::TargetName(hwy::SupportedAndGeneratedTargets().front()));
  return true;
}

// A kernel benchmark's main: the target chosen, then Google Benchmark's run.
inline int runBenchmarks(int argc, char** argv, const char* program) {
  if (!selectBenchTarget(program)) return 2;
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

}  // namespace sv::bench
