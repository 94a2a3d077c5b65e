// GLFW window context: runs only with a display (xvfb-run -a farfield_tests_gpu --gtest_filter=*Window*).
#include <gtest/gtest.h>

#include <cstdlib>
#include <memory>
#include <string>

#include "farfield/core/error.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/gl_barrier_check.h"
#include "farfield/gpu/gl_counters.h"
#include "farfield/gpu/renderer.h"
#include "farfield/scene/builtin.h"
#include "gpu/barrier_check_helpers.h"
#include "gpu/gpu_fixture.h"

namespace farfield::gpu {
namespace {

std::unique_ptr<Context> hiddenWindow() {
  ContextOptions options;
  options.platform = Platform::Window;
  options.window_visible = false;
  options.window_width = 320;
  options.window_height = 240;
  options.window_title = "farfield test";
  try {
    return Context::create(options);
  } catch (const Error& e) {
    // DISPLAY names no reachable X server: an environment problem, not a failure of the window code.
    if (std::string(e.what()).find("glfwInit failed") != std::string::npos) return nullptr;
    throw;
  }
}

TEST(GpuWindow, WindowContextRendersAndHandsBackToHeadless) {
  if (!std::getenv("DISPLAY")) GTEST_SKIP() << "DISPLAY not set";
  {
    const std::unique_ptr<Context> context = hiddenWindow();
    if (!context) GTEST_SKIP() << "glfwInit failed: no X server";
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

// A viewer's process may make no EGL context: FF_GL_BARRIER_CHECK must reach its window's GL calls too. Under ctest
// this test is a process of its own, so the window is its first context (before 2026-12-07 the GL counters
// installed only under an EGL context, and the viewer went unchecked: it hid a write after a read in the GPU crowd).
TEST(GpuWindow, AWindowsCallsAreCheckedForBarriers) {
  if (!std::getenv("DISPLAY")) GTEST_SKIP() << "DISPLAY not set";
  if (const char* c = std::getenv("FF_GL_COUNTERS"); c && std::string(c) == "0") GTEST_SKIP() << "FF_GL_COUNTERS=0";
  const char* before = std::getenv("FF_GL_BARRIER_CHECK");
  const std::string saved = before ? before : "";
  setenv("FF_GL_BARRIER_CHECK", "1", 1);
  const std::unique_ptr<Context> context = hiddenWindow();
  if (before) {
    setenv("FF_GL_BARRIER_CHECK", saved.c_str(), 1);
  } else {
    unsetenv("FF_GL_BARRIER_CHECK");
  }
  if (!context) GTEST_SKIP() << "glfwInit failed: no X server";
  ASSERT_TRUE(glCountersInstalled());
  ASSERT_TRUE(glBarrierCheckOn());
  setGlBarrierHazardsPrinted(false);  // made on purpose (ctest fails a test that prints one)
  clearGlBarrierHazards();

  const GLuint writer = test::computeProgram(R"(#version 450 core
layout(local_size_x = 1) in;
layout(std430, binding = 0) buffer Out { uint v[]; };
void main() { v[0] = 5u; })", "window-writer.comp");
  const GLuint reader = test::computeProgram(R"(#version 450 core
layout(local_size_x = 1) in;
layout(std430, binding = 0) readonly buffer In { uint v[]; };
layout(std430, binding = 1) buffer Sum { uint total; };
void main() { total += v[0]; })", "window-reader.comp");
  GLuint buffers[2] = {};
  glCreateBuffers(2, buffers);
  const uint32_t zeros[4] = {};
  for (GLuint b : buffers) glNamedBufferStorage(b, sizeof(zeros), zeros, GL_DYNAMIC_STORAGE_BIT);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, buffers[0]);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, buffers[1]);
  const auto run = [&](bool barrier) {
    glUseProgram(writer);
    glDispatchCompute(1, 1, 1);
    if (barrier) glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    glUseProgram(reader);
    glDispatchCompute(1, 1, 1);
    glMemoryBarrier(GL_ALL_BARRIER_BITS);
    return test::takeHazards();
  };
  EXPECT_EQ(run(true), "");
  const std::string missing = run(false);
  EXPECT_NE(missing.find("window-reader.comp"), std::string::npos) << missing;
  EXPECT_NE(missing.find("GL_SHADER_STORAGE_BARRIER_BIT"), std::string::npos) << missing;

  glDeleteProgram(writer);
  glDeleteProgram(reader);
  glDeleteBuffers(2, buffers);
  setGlBarrierHazardsPrinted(true);
  setGlBarrierCheck(false);
  enableGlBarrierCheckFromEnvironment(true);  // back as ctest runs every test
}

}  // namespace
}  // namespace farfield::gpu
