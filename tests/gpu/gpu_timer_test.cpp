#include "farfield/gpu/gpu_timer.h"

#include <gtest/gtest.h>

#include "farfield/core/timer.h"
#include "farfield/gpu/renderer.h"
#include "farfield/scene/builtin.h"
#include "gpu/gpu_fixture.h"

namespace farfield::gpu {
namespace {

using test::GpuTest;

// A draw heavy enough that rendering, not submission, is most of its wall time: 40 spheres of 16k triangles
// filling a 256x256 target.
struct HeavyDraw {
  GpuMesh sphere{scene::makeSphere(1.0f, 128, 64)};
  GpuMaterial material;
  Camera camera = test::testCamera(Vec3(0, -4, 0), Vec3(0.0f), 256);
  std::vector<DrawItem> items;
  HeavyDraw() {
    for (int i = 0; i < 40; ++i)
      items.push_back(DrawItem{&sphere, &material, glm::translate(Mat4(1.0f), Vec3(0.0f, 0.01f * float(i), 0.0f)),
                               uint32_t(i + 1)});
  }
};

TEST_F(GpuTest, TimerMeasuresWithinTheWallTime) {
  GpuTimer unused;
  EXPECT_EQ(unused.elapsedMs(), 0.0);  // never ran: no result, no GL error

  const GpuMesh cube(scene::makeUnitCube());
  const GpuMaterial material;
  const Camera camera = test::testCamera(Vec3(0, -3, 1), Vec3(0.0f), 128);
  RenderTarget target(128, 128);
  Renderer renderer;
  std::vector<DrawItem> items(50, DrawItem{&cube, &material, Mat4(1.0f), 1});
  for (int frame = 0; frame < 3; ++frame) {
    GpuTimer timer;
    Stopwatch wall;
    timer.begin();
    renderer.draw(camera, items, target);
    timer.end();
    const double ms = timer.elapsedMs();  // waits for the GPU
    const double wall_ms = wall.milliseconds();
    EXPECT_GE(ms, 0.0);
    EXPECT_LE(ms, wall_ms);
  }
}

TEST_F(GpuTest, TimerPicksTheClockForASoftwareRasterizer) {
  const GpuTimer timer;
  EXPECT_NE(timer.source(), GpuTimer::Source::Auto);
  EXPECT_EQ(timer.source() == GpuTimer::Source::CpuClock, currentRendererIsSoftware());
  EXPECT_EQ(GpuTimer(GpuTimer::Source::Query).source(), GpuTimer::Source::Query);
}

// The bench's pattern: frames drawn in turn into two targets (the reference, then the modes) with one timer each,
// some after a frame into the same target, some after a frame into the other. Every frame has a GPU time within its
// wall time, and on a software rasterizer most of it: the work is rendering. (llvmpipe's own GL_TIME_ELAPSED gave
// 15-30 percent of it exactly on the frames drawn after a frame into the same target.)
TEST_F(GpuTest, TimerCoversEveryFrameOfAHeavyDraw) {
  const HeavyDraw heavy;
  RenderTarget a(256, 256), b(256, 256);
  Renderer renderer;
  GpuTimer timer;
  RenderTarget* order[] = {&a, &b, &b, &a, &a, &b, &b, &b};
  for (int frame = 0; frame < 8; ++frame) {
    RenderTarget& target = *order[frame];
    target.bind();
    Stopwatch wall;
    timer.begin();
    target.clear(Vec4(0.0f, 0.0f, 0.0f, 1.0f));
    const FrameStats stats = renderer.draw(heavy.camera, heavy.items, target);
    timer.end();
    const double ms = timer.elapsedMs();
    const double wall_ms = wall.milliseconds();
    EXPECT_GT(stats.triangles, 600000u);
    EXPECT_GT(ms, 0.0) << "frame " << frame;
    EXPECT_LE(ms, wall_ms) << "frame " << frame;
    // On a software rasterizer the draw is CPU work in this process: nearly all of the wall time. (A hardware GPU
    // may finish such a draw in a fraction of the submission and synchronisation time.)
    if (currentRendererIsSoftware()) {
      EXPECT_GE(ms, 0.5 * wall_ms) << "frame " << frame << ": " << ms << " ms of " << wall_ms << " ms wall";
    }
  }
}

// The same through Renderer::render, which the bench's frame runner times frames with.
TEST_F(GpuTest, RendererGpuTimeOnConsecutiveFrames) {
  const HeavyDraw heavy;
  RenderTarget a(256, 256), b(256, 256);
  Renderer renderer;
  for (int frame = 0; frame < 8; ++frame) {
    RenderTarget& target = (frame % 3 == 0) ? a : b;
    const FrameStats stats = renderer.render(heavy.camera, heavy.items, target);
    EXPECT_GT(stats.gpu_ms, 0.0) << "frame " << frame;
    EXPECT_LE(stats.gpu_ms, stats.wall_ms) << "frame " << frame;
    if (currentRendererIsSoftware()) {
      EXPECT_GE(stats.gpu_ms, 0.5 * stats.wall_ms)
          << "frame " << frame << ": " << stats.gpu_ms << " ms of " << stats.wall_ms << " ms wall";
    }
  }
}

}  // namespace
}  // namespace farfield::gpu
