// A smaller target's frame over a larger one (gpu/target_upscaler.h): every pixel of the larger target is written,
// its colour the bilinear mix of the four nearest source texels, its id and depth the nearest texel's (or the far
// plane where depth is not scaled up, and 0 where ids are not), whatever the larger target held before. Checked against a CPU computation of
// the same mapping from the uploaded texels.
#include "farfield/gpu/target_upscaler.h"

#include <gtest/gtest.h>

#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "farfield/gpu/render_target.h"
#include "gpu/gpu_fixture.h"

namespace farfield::gpu {
namespace {

using test::GpuTest;

// Texels in GL's row order (row 0 at the bottom), as uploaded into the small target.
struct SourceTexels {
  int width = 0, height = 0;
  std::vector<image::Rgba8> color;
  std::vector<uint32_t> ids;
  std::vector<float> depth;
};

SourceTexels fillRandomly(const RenderTarget& target, uint32_t seed) {
  SourceTexels s{target.width(), target.height(), {}, {}, {}};
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> byte(0, 255);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (int i = 0; i < s.width * s.height; ++i) {
    s.color.push_back(image::Rgba8(byte(rng), byte(rng), byte(rng), 255));
    s.ids.push_back(rng());
    s.depth.push_back(unit(rng));
  }
  glTextureSubImage2D(target.colorTexture().handle(), 0, 0, 0, s.width, s.height, GL_RGBA, GL_UNSIGNED_BYTE,
                      s.color.data());
  glTextureSubImage2D(target.idTexture().handle(), 0, 0, 0, s.width, s.height, GL_RED_INTEGER, GL_UNSIGNED_INT,
                      s.ids.data());
  glTextureSubImage2D(target.depthTexture().handle(), 0, 0, 0, s.width, s.height, GL_DEPTH_COMPONENT, GL_FLOAT,
                      s.depth.data());
  return s;
}

void expectUpscaled(const SourceTexels& s, const RenderTarget& big, TargetUpscaler::Channels channels) {
  const image::ColorImage color = big.readColor();
  const image::IdImage ids = big.readIds();
  const image::DepthImage depth = big.readDepth();
  const double per_x = double(s.width) / big.width(), per_y = double(s.height) / big.height();
  auto texel = [&](int x, int y) { return size_t(std::clamp(y, 0, s.height - 1)) * size_t(s.width) +
                                          size_t(std::clamp(x, 0, s.width - 1)); };
  int color_off = 0, ids_off = 0, depth_off = 0;
  for (int y = 0; y < big.height(); ++y) {
    for (int x = 0; x < big.width(); ++x) {
      const double ax = (x + 0.5) * per_x, ay = (y + 0.5) * per_y;  // the pixel's centre in source texels
      const size_t nearest = texel(int(ax), int(ay));
      const int top_row = big.height() - 1 - y;  // readback rows run from the top
      const uint32_t want_id = channels == TargetUpscaler::Channels::Color ? 0u : s.ids[nearest];
      ids_off += ids.at(x, top_row) != want_id;
      const float want_depth = channels == TargetUpscaler::Channels::All ? s.depth[nearest] : 0.0f;  // else far
      depth_off += depth.at(x, top_row) != want_depth;
      const double tx = ax - 0.5, ty = ay - 0.5;
      const int x0 = int(std::floor(tx)), y0 = int(std::floor(ty));
      const double fx = tx - x0, fy = ty - y0;
      for (int c = 0; c < 3; ++c) {
        const double mixed = (1 - fy) * ((1 - fx) * s.color[texel(x0, y0)][c] + fx * s.color[texel(x0 + 1, y0)][c]) +
                             fy * ((1 - fx) * s.color[texel(x0, y0 + 1)][c] + fx * s.color[texel(x0 + 1, y0 + 1)][c]);
        // 8-bit filtering weights on a software rasterizer: within 2 of the exact mix.
        if (std::abs(double(color.at(x, top_row)[c]) - mixed) > 2.0) {
          ++color_off;
          break;
        }
      }
    }
  }
  EXPECT_EQ(ids_off, 0) << "pixels whose id is not the nearest texel's (or 0 without ids)";
  EXPECT_EQ(depth_off, 0) << "pixels whose depth is not the nearest texel's (or the far plane without depth)";
  EXPECT_EQ(color_off, 0) << "pixels whose colour is not the bilinear mix";
}

TEST_F(GpuTest, TheUpscaledFrameIsTheSmallFramesNearestIdsAndDepthAndItsBilinearColour) {
  TargetUpscaler upscaler;
  const int sizes[][4] = {{16, 9, 32, 18}, {37, 23, 100, 61}, {20, 20, 21, 47}};
  uint32_t seed = 1;
  using Channels = TargetUpscaler::Channels;
  for (const auto& size : sizes) {
    for (const Channels channels : {Channels::All, Channels::ColorAndIds, Channels::Color}) {
      SCOPED_TRACE(testing::Message() << size[0] << "x" << size[1] << " to " << size[2] << "x" << size[3]
                                      << (channels == Channels::All           ? ", all"
                                          : channels == Channels::ColorAndIds ? ", colour and ids"
                                                                              : ", colour"));
      RenderTarget small(size[0], size[1]), big(size[2], size[3]);
      const SourceTexels source = fillRandomly(small, seed++);
      // What the big target held before is nearer than anything (reversed Z: 1 is the near plane) and another colour:
      // the upscale must overwrite it all.
      big.clear(Vec4(1.0f, 0.0f, 1.0f, 1.0f));
      const GLuint stale_id = 77;  // and ids that are not 0
      glClearNamedFramebufferuiv(big.framebuffer(), GL_COLOR, 1, &stale_id);
      const float near_depth = 1.0f;
      big.bind();
      glDepthMask(GL_TRUE);
      glClearBufferfv(GL_DEPTH, 0, &near_depth);
      upscaler.draw(small, big, channels);
      expectUpscaled(source, big, channels);
    }
  }
  EXPECT_EQ(glGetError(), GLenum(GL_NO_ERROR));
}

}  // namespace
}  // namespace farfield::gpu
