// GLFW window context: runs only with a display (xvfb-run -a farfield_tests_gpu --gtest_filter=*Window*).
#include <gtest/gtest.h>

#include <cstdlib>
#include <memory>
#include <string>

#include "farfield/core/error.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/renderer.h"
#include "farfield/scene/builtin.h"
#include "gpu/gpu_fixture.h"

namespace farfield::gpu {
namespace {

TEST(GpuWindow, WindowContextRendersAndHandsBackToHeadless) {
  if (!std::getenv("DISPLAY")) GTEST_SKIP() << "DISPLAY not set";
  {
    ContextOptions options;
    options.platform = Platform::Window;
    options.window_visible = false;
    options.window_width = 320;
    options.window_height = 240;
    options.window_title = "farfield test";
    std::unique_ptr<Context> context;
    try {
      context = Context::create(options);
    } catch (const Error& e) {
      // DISPLAY names no reachable X server: an environment problem, not a failure of the window code.
      if (std::string(e.what()).find("glfwInit failed") != std::string::npos) GTEST_SKIP() << e.what();
      throw;
    }
    EXPECT_EQ(context->info().platform, "glfw-window");
    EXPECT_GE(context->info().major * 10 + context->info().minor, 45);
    EXPECT_TRUE(context->info().core_profile);
    EXPECT_NE(context->nativeWindow(), nullptr);
    int width = 0, height = 0;
    context->framebufferSize(width, height);
    EXPECT_EQ(width, 320);
    EXPECT_EQ(height, 240);
    EXPECT_FALSE(context->shouldClose());

    // Off-screen rendering works in the window's context too.
    Renderer renderer;
    const GpuMesh cube(scene::makeUnitCube());
    const GpuMaterial material;
    const Camera camera = test::testCamera(Vec3(0, -4, 0), Vec3(0.0f), 64);
    RenderTarget target(64, 64);
    const DrawItem item{&cube, &material, Mat4(1.0f), 4};
    renderer.render(camera, {&item, 1}, target);
    EXPECT_EQ(target.readIds().at(32, 32), 4u);
    context->swapBuffers();
  }
  // The shared headless context comes back and still renders.
  sharedHeadlessContext();
  Renderer renderer;
  const GpuMesh cube(scene::makeUnitCube());
  const GpuMaterial material;
  const Camera camera = test::testCamera(Vec3(0, -4, 0), Vec3(0.0f), 32);
  RenderTarget target(32, 32);
  const DrawItem item{&cube, &material, Mat4(1.0f), 6};
  renderer.render(camera, {&item, 1}, target);
  EXPECT_EQ(target.readIds().at(16, 16), 6u);
}

}  // namespace
}  // namespace farfield::gpu
