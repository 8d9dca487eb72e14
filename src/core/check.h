// Checks of preconditions and invariants (STYLE.md habit 9): SV_CHECK is always on, for what a
// caller must guarantee and a comment used to ask for; SV_DCHECK is on in debug builds and in the
// sanitizer builds scripts/test runs (SV_ENABLE_DCHECK, set by SV_SANITIZE), for hot loops. A failed check prints file and line, the condition and — for the comparisons — both
// operands, then aborts. Input errors are not checks: they are values (synthvis/result.h).
#pragma once

#include <fmt/format.h>

#include <string>

namespace sv::core {

// Prints "file:line: check failed: condition (detail)" to stderr and aborts.
[[noreturn]] void checkFailed(const char* file, int line, const char* condition,
                              const std::string& detail = {});

}  // namespace sv::core

#define SV_CHECK(condition)                                                    \
  do {                                                                         \
    if (!(condition)) ::sv::core::checkFailed(__FILE__, __LINE__, #condition); \
  } while (0)

// SV_CHECK_OP(a, op, b): a op b, both operands printed when it fails.
#define SV_CHECK_OP(a, op, b)                                                 \
  do {                                                                        \
    const auto& svCheckA = (a);                                               \
    const auto& svCheckB = (b);                                               \
    if (!(svCheckA op svCheckB))                                              \
      ::sv::core::checkFailed(__FILE__, __LINE__, #a " " #op " " #b,          \
                              ::fmt::format("{} vs {}", svCheckA, svCheckB)); \
  } while (0)
#define SV_CHECK_EQ(a, b) SV_CHECK_OP(a, ==, b)
#define SV_CHECK_NE(a, b) SV_CHECK_OP(a, !=, b)
#define SV_CHECK_LT(a, b) SV_CHECK_OP(a, <, b)
#define SV_CHECK_LE(a, b) SV_CHECK_OP(a, <=, b)
#define SV_CHECK_GE(a, b) SV_CHECK_OP(a, >=, b)
#define SV_CHECK_GT(a, b) SV_CHECK_OP(a, >, b)

#if defined(NDEBUG) && !defined(SV_ENABLE_DCHECK)
#define SV_DCHECK(condition) \
  do {                       \
  } while (false && (condition))
#define SV_DCHECK_OP(a, op, b) \
  do {                         \
  } while (false && ((a)op(b)))
#else
#define SV_DCHECK(condition) SV_CHECK(condition)
#define SV_DCHECK_OP(a, op, b) SV_CHECK_OP(a, op, b)
#endif
#define SV_DCHECK_EQ(a, b) SV_DCHECK_OP(a, ==, b)
#define SV_DCHECK_NE(a, b) SV_DCHECK_OP(a, !=, b)
#define SV_DCHECK_LT(a, b) SV_DCHECK_OP(a, <, b)
#define SV_DCHECK_LE(a, b) SV_DCHECK_OP(a, <=, b)
#define SV_DCHECK_GE(a, b) SV_DCHECK_OP(a, >=, b)
#define SV_DCHECK_GT(a, b) SV_DCHECK_OP(a, >, b)
