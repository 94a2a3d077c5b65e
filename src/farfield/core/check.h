// FF_CHECK: internal invariants. A failed check is a bug in Farfield, not bad input: it prints file:line and aborts.
#pragma once

#include <cstdio>
#include <cstdlib>

namespace farfield::detail {
[[noreturn]] inline void checkFailed(const char* expr, const char* file, int line, const char* msg) {
  std::fprintf(stderr, "%s:%d: FF_CHECK(%s) failed%s%s\n", file, line, expr, msg ? ": " : "", msg ? msg : "");
  std::fflush(stderr);
  std::abort();
}
}  // namespace farfield::detail

#define FF_CHECK(cond) \
  do { if (!(cond)) ::farfield::detail::checkFailed(#cond, __FILE__, __LINE__, nullptr); } while (0)
#define FF_CHECK_MSG(cond, msg) \
  do { if (!(cond)) ::farfield::detail::checkFailed(#cond, __FILE__, __LINE__, (msg)); } while (0)
