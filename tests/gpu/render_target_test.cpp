#include "farfield/gpu/render_target.h"

#include <gtest/gtest.h>

#include "farfield/gpu/renderer.h"
#include "gpu/gpu_fixture.h"

namespace farfield::gpu {
namespace {

using test::GpuTest;

TEST_F(GpuTest, ClearedTargetReadsBackClearValues) {
  RenderTarget target(37, 21);  // odd sizes: no row padding assumptions
  EXPECT_EQ(target.width(), 37);
  EXPECT_EQ(target.height(), 21);
  target.clear(Vec4(0.2f, 0.4f, 0.6f, 1.0f));
  const image::ColorImage color = target.readColor();
  const image::DepthImage depth = target.readDepth();
  const image::IdImage ids = target.readIds();
  ASSERT_EQ(color.width(), 37);
  ASSERT_EQ(color.height(), 21);
  ASSERT_EQ(depth.width(), 37);
  ASSERT_EQ(ids.height(), 21);
  for (const auto& c : color.pixels()) ASSERT_EQ(c, image::Rgba8(51, 102, 153, 255));
  for (float d : depth.pixels()) ASSERT_EQ(d, 0.0f);  // reversed Z: far
  for (uint32_t id : ids.pixels()) ASSERT_EQ(id, 0u);
}

TEST_F(GpuTest, EmptyFrameIsSkyEverywhere) {
  Renderer renderer;
  RenderTarget target(64, 48);
  Camera camera = test::testCamera(Vec3(0, -5, 1), Vec3(0, 0, 1));
  camera.width = 64;
  camera.height = 48;
  const FrameStats stats = renderer.render(camera, {}, target);
  EXPECT_EQ(stats.triangles, 0u);
  EXPECT_EQ(stats.draw_calls, 0u);
  EXPECT_EQ(stats.objects, 0u);
  EXPECT_GE(stats.wall_ms, 0.0);
  const image::ColorImage color = target.readColor();
  for (const auto& c : color.pixels()) ASSERT_TRUE(test::colorNear(c, test::skyColor(renderer.light()), 1));
  const image::IdImage ids = target.readIds();
  for (uint32_t id : ids.pixels()) ASSERT_EQ(id, 0u);
}

TEST_F(GpuTest, MovedTargetKeepsItsImages) {
  RenderTarget a(8, 8);
  a.clear(Vec4(1.0f, 0.0f, 0.0f, 1.0f));
  RenderTarget b = std::move(a);
  EXPECT_EQ(a.framebuffer(), 0u);
  EXPECT_EQ(b.width(), 8);
  EXPECT_EQ(b.readColor().at(3, 3), image::Rgba8(255, 0, 0, 255));
}

}  // namespace
}  // namespace farfield::gpu
