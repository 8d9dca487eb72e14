// The free-form tests' runs over every compiled SIMD target (Highway): the kernels must give every
// target the same answers.
#pragma once

#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <cstdint>
#include <cstring>
#include <vector>

namespace sv::freeform {

// Runs fn(target) with each compiled SIMD target selected; returns how many ran.
template <class Fn>
int forEveryTarget(const Fn& fn) {
  int targets = 0;
  for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
    hwy::SetSupportedTargetsForTest(target);
    ++targets;
    fn(target);
  }
  hwy::SetSupportedTargetsForTest(0);
  return targets;
}

// Runs body(target, results) on every compiled SIMD target: the results of each, bit for bit those
// of the first one tried.
template <class Body>
void onEveryTarget(const Body& body) {
  std::vector<double> first;
  int seen = 0;
  const int targets = forEveryTarget([&](int64_t target) {
    std::vector<double> results;
    body(target, results);
    if (seen++ == 0) {
      first = std::move(results);
      return;
    }
    ASSERT_EQ(results.size(), first.size());
    EXPECT_EQ(0, std::memcmp(results.data(), first.data(), first.size() * sizeof(double)))
        << hwy::TargetName(target) << " differs from the first target";
  });
  EXPECT_GE(targets, 1);
}

}  // namespace sv::freeform
