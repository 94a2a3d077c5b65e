// Allocator set-up for timed runs. llvmpipe allocates and frees tens of megabytes per frame (bins, vertex buffers,
// tiles); with glibc's default malloc that memory is returned to the kernel (trim of the heap top, munmap of blocks
// over the mmap threshold) and faulted back in on the next frame, which measured 87 ms instead of 28 ms a frame for
// `farfield bench --modes culled` on the demo city. Timed commands call configureTimingAllocator() first, so that
// frame times measure rendering, not page faults.
#pragma once

#include <cstddef>
#include <string>

namespace farfield {

// Whether this build runs under a sanitizer, whose allocator ignores mallopt (the settings below are then not applied).
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
inline constexpr bool kSanitizerBuild = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
inline constexpr bool kSanitizerBuild = true;
#else
inline constexpr bool kSanitizerBuild = false;
#endif
#else
inline constexpr bool kSanitizerBuild = false;
#endif


struct AllocatorSettings {
  bool applied = false;          // the settings are in effect (glibc, every mallopt call accepted)
  size_t trim_threshold = 0;     // bytes of free memory at a heap top before it is given back (M_TRIM_THRESHOLD)
  size_t mmap_threshold = 0;     // allocations at least this large get their own mmap (M_MMAP_THRESHOLD)
  size_t top_pad = 0;            // extra bytes asked of the kernel whenever a heap grows (M_TOP_PAD)
  std::string description;       // one line for reports: what was set, or why nothing was
};

// The values, as GLIBC_TUNABLES=glibc.malloc.trim_threshold=4294967295:glibc.malloc.mmap_threshold=33554432:
// glibc.malloc.top_pad=268435456 would set them. mallopt takes an int, so the trim threshold is INT_MAX (2 GiB - 1)
// rather than 4 GiB - 1: either way no heap top is trimmed during a run.
inline constexpr size_t kTimingTrimThreshold = 2147483647u;
inline constexpr size_t kTimingMmapThreshold = 32u << 20;  // glibc's largest (HEAP_MAX_SIZE / 2 on 64-bit)
inline constexpr size_t kTimingTopPad = 256u << 20;

// Applies the settings above with mallopt (glibc only) and returns what was done. Call it at the start of a timed
// command, before the allocations it should govern (mallopt also turns off glibc's dynamic mmap threshold).
// No-op, with `applied` false and a description saying why, when:
//   - the C library is not glibc (mallopt does not exist or means something else);
//   - the process runs under a sanitizer (its allocator replaces malloc and ignores mallopt);
//   - the environment has FF_ALLOCATOR=default (keeps glibc's defaults and any GLIBC_TUNABLES, to measure them).
// The description names GLIBC_TUNABLES when it is set. Idempotent; the last result is kept for reports.
AllocatorSettings configureTimingAllocator();

// What configureTimingAllocator() last did in this process, or (never called) `applied` false and a description
// saying that the C library's defaults are in effect. For reports (bench.json, report.md).
AllocatorSettings currentAllocatorSettings();

}  // namespace farfield
