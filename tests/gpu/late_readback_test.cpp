// Reading GPU results frames later (gpu/late_readback.h): captures come back in order with the bytes the buffer held
// when each was made, a full ring skips and counts, nothing in a capture waits for the GPU; timed stretches come back
// once each, with their frames.
#include "farfield/gpu/late_readback.h"

#include <gtest/gtest.h>

#include <epoxy/gl.h>

#include <chrono>
#include <cstring>
#include <thread>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/gpu/gl_counters.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/stage_clock.h"
#include "gpu/gpu_fixture.h"

namespace farfield::gpu {
namespace {

using test::GpuTest;

TEST_F(GpuTest, LateReadbackReturnsEachCaptureInOrderWithItsBytes) {
  installGlCounters();
  GLuint source = 0;
  glCreateBuffers(1, &source);
  glNamedBufferStorage(source, 16, nullptr, GL_DYNAMIC_STORAGE_BIT);
  LateReadback late(8, 3);
  EXPECT_EQ(late.bytes(), 8u);
  const GlCounters before = glCounters();
  for (uint32_t frame = 1; frame <= 4; ++frame) {
    const uint32_t values[4] = {10 * frame, 10 * frame + 1, 10 * frame + 2, 10 * frame + 3};
    glNamedBufferSubData(source, 0, sizeof(values), values);  // the GPU's copy is ordered after this
    EXPECT_EQ(late.capture(source, 4, frame), frame <= 3) << "frame " << frame << ": three slots";
  }
  if (glCountersInstalled()) {
    EXPECT_EQ((glCounters() - before).syncs, 0u) << "capturing waits for nothing";
  }
  EXPECT_EQ(late.skipped(), 1u);
  glFinish();
  std::vector<uint64_t> frames;
  std::vector<uint32_t> firsts;
  EXPECT_EQ(late.finished([&](uint64_t frame, std::span<const uint8_t> bytes) {
              ASSERT_EQ(bytes.size(), 8u);
              uint32_t v[2];
              std::memcpy(v, bytes.data(), 8);
              frames.push_back(frame);
              firsts.push_back(v[0]);
              EXPECT_EQ(v[1], v[0] + 1);
            }),
            3u);
  EXPECT_EQ(frames, (std::vector<uint64_t>{1, 2, 3}));
  EXPECT_EQ(firsts, (std::vector<uint32_t>{11, 21, 31}));  // from byte offset 4
  EXPECT_EQ(late.finished([](uint64_t, std::span<const uint8_t>) {}), 0u) << "each capture comes back once";
  EXPECT_TRUE(late.capture(source, 0, 5));  // the slots are free again
  glDeleteBuffers(1, &source);
  EXPECT_EQ(glGetError(), GLenum(GL_NO_ERROR));
  EXPECT_THROW(LateReadback(0), Error);  // nothing to read
}

TEST_F(GpuTest, LateTimerReturnsEachFrameOnce) {
  LateTimer timer(2);
  RenderTarget target(64, 64);
  for (uint64_t frame = 1; frame <= 3; ++frame) {
    timer.begin(frame);
    target.clear(Vec4(0.1f * float(frame)));
    timer.end();
  }
  EXPECT_EQ(timer.skipped(), 1u) << "the third frame found both slots in flight";
  glFinish();
  std::vector<uint64_t> frames;
  timer.finished([&](uint64_t frame, double ms) {
    frames.push_back(frame);
    EXPECT_GE(ms, 0.0);
  });
  EXPECT_EQ(frames, (std::vector<uint64_t>{1, 2}));
  EXPECT_EQ(timer.finished([](uint64_t, double) {}), 0u);
  EXPECT_EQ(glGetError(), GLenum(GL_NO_ERROR));
}

// Stage times: each frame comes back once with one time per stage, a mark left out gives its stage 0, and a full ring
// skips; with either source (timestamp queries are only mechanics on a software rasterizer, whose clock the CPU source
// stands in for). On the CPU clock a stage that waits kWaitMs takes at least that long: a bound, not a race between two
// stages' times, which a loaded CI machine can reorder.
TEST_F(GpuTest, StageClockReturnsEachFrameWithItsStages) {
  constexpr double kWaitMs = 15.0;
  for (const GpuTimer::Source source : {GpuTimer::Source::Auto, GpuTimer::Source::Query}) {
    SCOPED_TRACE(source == GpuTimer::Source::Auto ? "auto" : "query");
    StageClock clock(4, 2, source);
    EXPECT_EQ(clock.stages(), 3u);
    RenderTarget big(1024, 1024), small(8, 8);
    for (uint64_t frame = 1; frame <= 3; ++frame) {
      clock.beginFrame(frame);
      for (int k = 0; k < 20; ++k) big.clear(Vec4(0.05f * float(k)));  // stage 0: work
      std::this_thread::sleep_for(std::chrono::duration<double, std::milli>(kWaitMs));
      clock.mark(1);
      small.clear(Vec4(0.5f));  // stage 1: next to nothing
      // mark 2 left out: stage 2 takes 0, stage 1 runs to mark 3
      clock.mark(3);
    }
    EXPECT_EQ(clock.skipped(), 1u) << "the third frame found both slots in flight";
    glFinish();
    std::vector<uint64_t> frames;
    clock.finished([&](uint64_t frame, std::span<const double> ms) {
      frames.push_back(frame);
      ASSERT_EQ(ms.size(), 3u);
      for (double m : ms) EXPECT_GE(m, 0.0);
      EXPECT_EQ(ms[2], 0.0);
      if (clock.source() == GpuTimer::Source::CpuClock) {
        EXPECT_GE(ms[0], kWaitMs);
      }
    });
    EXPECT_EQ(frames, (std::vector<uint64_t>{1, 2}));
    EXPECT_EQ(clock.finished([](uint64_t, std::span<const double>) {}), 0u) << "each frame comes back once";
    EXPECT_EQ(glGetError(), GLenum(GL_NO_ERROR));
  }
}

}  // namespace
}  // namespace farfield::gpu
