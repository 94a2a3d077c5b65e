#include "farfield/gpu/gpu_timer.h"

#include <gtest/gtest.h>

#include "farfield/core/timer.h"
#include "farfield/gpu/renderer.h"
#include "farfield/scene/builtin.h"
#include "gpu/gpu_fixture.h"

namespace farfield::gpu {
namespace {

using test::GpuTest;

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

}  // namespace
}  // namespace farfield::gpu
