#include "farfield/core/allocator.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <vector>

#if defined(__GLIBC__)
#include <malloc.h>
#include <sys/wait.h>
#include <unistd.h>
#endif

using namespace farfield;

namespace {

#if defined(__GLIBC__)
// What glibc's heap does, seen through mallinfo2 (bytes): the heap's growth when it must ask the kernel for more,
// whether a freed top is kept, and whether a large block is mmapped.
struct HeapProbe {
  bool applied = false;
  bool grew = false;
  size_t growth = 0;          // arena bytes added by the first allocation that made the heap grow
  size_t trimmed = 0;         // arena bytes given back when everything allocated was freed again
  size_t mmapped_big = 0;     // mmapped bytes added by one 24 MiB allocation
};

HeapProbe probeHeap() {
  HeapProbe p;
  // 64 KiB blocks (under any mmap threshold: the default is 128 KiB) until the heap grows; the growth is the
  // request plus the top pad.
  std::vector<void*> blocks;
  blocks.reserve(8192);  // before the first measurement: a growing vector must not sit on the heap top
  const size_t start = mallinfo2().arena;
  size_t arena = start;
  for (int i = 0; i < 8192 && !p.grew; ++i) {
    void* b = std::malloc(64u << 10);
    if (!b) break;
    static_cast<volatile char*>(b)[0] = 1;
    blocks.push_back(b);
    const size_t now = mallinfo2().arena;
    if (now > arena) {
      p.grew = true;
      p.growth = now - arena;
    }
    arena = now;
  }
  const size_t peak = mallinfo2().arena;
  for (void* b : blocks) std::free(b);
  const size_t end = mallinfo2().arena;
  p.trimmed = peak > end ? peak - end : 0;
  // 24 MiB: above glibc's default mmap threshold (128 KiB, raised dynamically only as far as the largest mmapped
  // block freed so far, which is why this comes after the trim probe), below the timing threshold (32 MiB).
  {
    const size_t before = mallinfo2().hblkhd;
    void* volatile big = std::malloc(24u << 20);  // volatile: the compiler must not elide the pair
    static_cast<volatile char*>(big)[0] = 1;
    const size_t after = mallinfo2().hblkhd;
    p.mmapped_big = after > before ? after - before : 0;
    std::free(big);
  }
  return p;
}

// Runs probeHeap in a child process, after configureTimingAllocator() when `configure`: each side starts from the
// state of this test process, and neither leaves its settings behind.
HeapProbe probeInChild(bool configure) {
  int fds[2];
  if (pipe(fds) != 0) ADD_FAILURE() << "pipe failed";
  const pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    HeapProbe p;
    if (configure) p.applied = configureTimingAllocator().applied;
    const HeapProbe measured = probeHeap();
    p.grew = measured.grew;
    p.growth = measured.growth;
    p.trimmed = measured.trimmed;
    p.mmapped_big = measured.mmapped_big;
    const ssize_t n = write(fds[1], &p, sizeof(p));
    _exit(n == ssize_t(sizeof(p)) ? 0 : 1);
  }
  close(fds[1]);
  HeapProbe p;
  const ssize_t n = read(fds[0], &p, sizeof(p));
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  EXPECT_EQ(n, ssize_t(sizeof(p)));
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  return p;
}
#endif

}  // namespace

TEST(Allocator, CurrentSettingsBeforeAnyCallSayDefaults) {
  // This test binary calls configureTimingAllocator only in child processes.
  const AllocatorSettings s = currentAllocatorSettings();
  EXPECT_FALSE(s.applied);
  EXPECT_NE(s.description.find("defaults"), std::string::npos) << s.description;
}

#if defined(__GLIBC__)
TEST(Allocator, TimingSettingsChangeWhatTheHeapDoes) {
  if (kSanitizerBuild) GTEST_SKIP() << "a sanitizer's allocator ignores mallopt";
  const HeapProbe plain = probeInChild(false);
  const HeapProbe timed = probeInChild(true);
  ASSERT_TRUE(timed.applied);
  ASSERT_TRUE(plain.grew && timed.grew);
  // The oracle: glibc's defaults grow the heap by little more than the request (top pad 128 KiB), map 24 MiB blocks
  // of their own and give a freed heap top back; the timing settings do none of that.
  EXPECT_LT(plain.growth, kTimingTopPad / 4);
  EXPECT_GE(timed.growth, kTimingTopPad);
  EXPECT_GE(plain.mmapped_big, size_t(24u << 20));
  EXPECT_EQ(timed.mmapped_big, 0u);
  EXPECT_GT(plain.trimmed, 0u);
  EXPECT_EQ(timed.trimmed, 0u);
}

TEST(Allocator, ReportsWhatItSetAndRemembersIt) {
  if (kSanitizerBuild) GTEST_SKIP() << "a sanitizer's allocator ignores mallopt";
  const pid_t pid = fork();
  if (pid == 0) {
    const AllocatorSettings s = configureTimingAllocator();
    const AllocatorSettings again = configureTimingAllocator();  // idempotent
    const AllocatorSettings current = currentAllocatorSettings();
    const bool ok = s.applied && s.trim_threshold == kTimingTrimThreshold &&
                    s.mmap_threshold == kTimingMmapThreshold && s.top_pad == kTimingTopPad &&
                    s.description.find("256 MiB") != std::string::npos && again.applied &&
                    current.description == s.description;
    _exit(ok ? 0 : 1);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
}

TEST(Allocator, EnvironmentKeepsTheDefaults) {
  const pid_t pid = fork();
  if (pid == 0) {
    setenv("FF_ALLOCATOR", "default", 1);
    const AllocatorSettings s = configureTimingAllocator();
    const bool ok = !s.applied && s.top_pad == 0 && s.description.find("FF_ALLOCATOR=default") != std::string::npos;
    _exit(ok ? 0 : 1);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
}
#endif
