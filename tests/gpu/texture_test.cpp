#include "farfield/gpu/texture.h"

#include <gtest/gtest.h>

#include "farfield/core/error.h"
#include "farfield/gpu/renderer.h"
#include "gpu/gpu_fixture.h"

namespace farfield::gpu {
namespace {

using test::GpuTest;

// 4 x 4 image in four 2 x 2 quadrants: red top-left, green top-right, blue bottom-left, transparent bottom-right.
image::ColorImage quadrantImage() {
  image::ColorImage img(4, 4);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) {
      const bool right = x >= 2, bottom = y >= 2;
      img.at(x, y) = !bottom ? (right ? image::Rgba8(0, 255, 0, 255) : image::Rgba8(255, 0, 0, 255))
                             : (right ? image::Rgba8(255, 255, 255, 0) : image::Rgba8(0, 0, 255, 255));
    }
  return img;
}

TEST_F(GpuTest, TexturedQuadShowsTheTextureColours) {
  // Quad facing the camera (at -y), uv (0, 0) at its top-left corner: the image appears upright.
  scene::Mesh quad;
  quad.positions = {{-1, 0, 1}, {-1, 0, -1}, {1, 0, -1}, {1, 0, 1}};  // top-left, bottom-left, bottom-right, top-right
  quad.normals.assign(4, Vec3(0, -1, 0));
  quad.uvs = {{0, 0}, {0, 1}, {1, 1}, {1, 0}};
  quad.indices = {0, 1, 2, 0, 2, 3};
  const GpuMesh mesh(quad);
  const Texture texture = Texture::fromImage(quadrantImage());
  EXPECT_EQ(texture.width(), 4);
  EXPECT_EQ(texture.format(), TextureFormat::Rgba8);
  GpuMaterial material;
  material.texture = &texture;
  material.unlit = true;
  const Camera camera = test::testCamera(Vec3(0, -3, 0), Vec3(0.0f), 96);
  RenderTarget target(96, 96);
  Renderer renderer;
  const DrawItem item{&mesh, &material, Mat4(1.0f), 9};
  renderer.render(camera, {&item, 1}, target);
  const image::ColorImage color = target.readColor();
  const image::IdImage ids = target.readIds();

  const IVec2 top_left = test::pixelOf(camera, Vec3(-0.5f, 0.0f, 0.5f));
  const IVec2 top_right = test::pixelOf(camera, Vec3(0.5f, 0.0f, 0.5f));
  const IVec2 bottom_left = test::pixelOf(camera, Vec3(-0.5f, 0.0f, -0.5f));
  const IVec2 bottom_right = test::pixelOf(camera, Vec3(0.5f, 0.0f, -0.5f));
  EXPECT_TRUE(test::colorNear(color.at(top_left.x, top_left.y), Vec3(1, 0, 0)));
  EXPECT_TRUE(test::colorNear(color.at(top_right.x, top_right.y), Vec3(0, 1, 0)));
  EXPECT_TRUE(test::colorNear(color.at(bottom_left.x, bottom_left.y), Vec3(0, 0, 1)));
  EXPECT_EQ(ids.at(top_left.x, top_left.y), 9u);
  // Transparent texels are cut out: sky colour, no id, no depth.
  EXPECT_TRUE(test::colorNear(color.at(bottom_right.x, bottom_right.y), test::skyColor(renderer.light()), 1));
  EXPECT_EQ(ids.at(bottom_right.x, bottom_right.y), 0u);
  EXPECT_EQ(target.readDepth().at(bottom_right.x, bottom_right.y), 0.0f);

  // The base colour multiplies the texture.
  material.base_color = Vec4(0.5f, 1.0f, 1.0f, 1.0f);
  renderer.render(camera, {&item, 1}, target);
  EXPECT_TRUE(test::colorNear(target.readColor().at(top_left.x, top_left.y), Vec3(0.5f, 0, 0)));

  // Item-buffer mode samples no texture: the transparent quadrant is drawn too.
  renderer.render(camera, {&item, 1}, target, RenderMode::ItemBuffer);
  EXPECT_EQ(target.readIds().at(bottom_right.x, bottom_right.y), 9u);
}

TEST_F(GpuTest, TextureUploadReplacesTheImage) {
  Texture texture = Texture::fromImage(quadrantImage(), false);
  image::ColorImage white(4, 4, image::Rgba8(255, 255, 255, 255));
  texture.upload(white);
  scene::Mesh quad;
  quad.positions = {{-1, 0, 1}, {-1, 0, -1}, {1, 0, -1}, {1, 0, 1}};
  quad.uvs = {{0, 0}, {0, 1}, {1, 1}, {1, 0}};
  quad.indices = {0, 1, 2, 0, 2, 3};
  const GpuMesh mesh(quad);
  GpuMaterial material;
  material.texture = &texture;
  material.unlit = true;
  const Camera camera = test::testCamera(Vec3(0, -3, 0), Vec3(0.0f), 64);
  RenderTarget target(64, 64);
  Renderer renderer;
  const DrawItem item{&mesh, &material, Mat4(1.0f), 1};
  renderer.render(camera, {&item, 1}, target);
  EXPECT_TRUE(test::colorNear(target.readColor().at(32, 32), Vec3(1.0f)));
}

TEST_F(GpuTest, TextureFormatsAndSizes) {
  for (TextureFormat format : {TextureFormat::Rgba8, TextureFormat::R32F, TextureFormat::Depth32F,
                               TextureFormat::R32UI}) {
    Texture t(16, 8, format);
    EXPECT_NE(t.handle(), 0u);
    EXPECT_EQ(t.width(), 16);
    EXPECT_EQ(t.height(), 8);
    EXPECT_EQ(t.format(), format);
    EXPECT_EQ(t.byteSize(), 16u * 8u * 4u);
  }
  EXPECT_THROW(Texture(0, 8, TextureFormat::Rgba8), Error);
  EXPECT_THROW(Texture::fromImage(image::ColorImage()), Error);
}

}  // namespace
}  // namespace farfield::gpu
