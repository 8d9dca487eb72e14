// The tests' main: GoogleTest's, and with SV_TEST_SIMD_TARGET=scalar every kernel on Highway's
// scalar fallback alone (HWY_BASELINE_SCALAR: HWY_EMU128, or HWY_SCALAR where the compiler's
// EMU128 is broken, as g++ 12.2's) — the permanent scalar path, the same target code an SV_NO_SIMD
// build compiles alone — on which scripts/test runs the kernels' tests without a build of their
// own.
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>

int main(int argc, char** argv) {
  if (const char* target = std::getenv("SV_TEST_SIMD_TARGET"); target && *target) {
    if (std::strcmp(target, "scalar") != 0) {
      std::fprintf(stderr, "SV_TEST_SIMD_TARGET=%s: only scalar is known\n", target);
      return 2;
    }
    hwy::SetSupportedTargetsForTest(HWY_BASELINE_SCALAR);
  }
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
