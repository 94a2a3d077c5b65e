#include "farfield/core/allocator.h"

#include <climits>
#include <cstdlib>
#include <mutex>
#include <optional>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace farfield {
namespace {

std::mutex g_mutex;
std::optional<AllocatorSettings> g_last;

std::string tunablesNote() {
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  return (tunables && *tunables) ? std::string("; GLIBC_TUNABLES=") + tunables : std::string();
}

std::string mib(size_t bytes) { return std::to_string(bytes >> 20) + " MiB"; }

AllocatorSettings apply() {
  AllocatorSettings s;
  if (const char* env = std::getenv("FF_ALLOCATOR"); env && std::string(env) == "default") {
    s.description = "C library malloc defaults (FF_ALLOCATOR=default)" + tunablesNote();
    return s;
  }
  if (kSanitizerBuild) {
    s.description = "sanitizer allocator (mallopt has no effect); malloc settings left alone";
    return s;
  }
#if defined(__GLIBC__)
  // mallopt returns 1 on success, 0 for a value it rejects. The order does not matter; each call also disables the
  // dynamic mmap threshold (which would otherwise raise the mmap threshold, and with it the trim threshold, as blocks
  // are freed, so that the behaviour changed during a run).
  const bool trim = mallopt(M_TRIM_THRESHOLD, int(kTimingTrimThreshold)) == 1;
  const bool mmap = mallopt(M_MMAP_THRESHOLD, int(kTimingMmapThreshold)) == 1;
  const bool pad = mallopt(M_TOP_PAD, int(kTimingTopPad)) == 1;
  s.applied = trim && mmap && pad;
  if (trim) s.trim_threshold = kTimingTrimThreshold;
  if (mmap) s.mmap_threshold = kTimingMmapThreshold;
  if (pad) s.top_pad = kTimingTopPad;
  s.description = std::string(s.applied ? "glibc malloc tuned for timing" : "glibc mallopt partly rejected") +
                  " (mallopt: trim threshold " + (trim ? "2 GiB" : "rejected") + ", mmap threshold " +
                  (mmap ? mib(kTimingMmapThreshold) : "rejected") + ", top pad " +
                  (pad ? mib(kTimingTopPad) : "rejected") + ": freed memory is kept for the next frame)" +
                  tunablesNote();
#else
  s.description = "not glibc: the C library's malloc defaults (no mallopt settings applied)";
#endif
  return s;
}

}  // namespace

AllocatorSettings configureTimingAllocator() {
  AllocatorSettings s = apply();
  std::lock_guard<std::mutex> lock(g_mutex);
  g_last = s;
  return s;
}

AllocatorSettings currentAllocatorSettings() {
  std::lock_guard<std::mutex> lock(g_mutex);
  if (g_last) return *g_last;
  AllocatorSettings s;
  s.description = "C library malloc defaults (configureTimingAllocator was not called)" + tunablesNote();
  return s;
}

}  // namespace farfield
