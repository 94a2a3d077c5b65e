#include "farfield/gpu/gpu_depth_pyramid.h"

#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "farfield/gpu/render_target.h"
#include "gpu/gpu_fixture.h"

namespace farfield::gpu {
namespace {

using test::GpuTest;

// Level k's texel (x, y) by brute force: the farthest (smallest) depth over the level-0 pixels it stands for, the
// block [x 2^k, (x + 1) 2^k - 1] x [y 2^k, (y + 1) 2^k - 1] clamped to the image (levels round their sizes up).
float bruteTexel(const std::vector<float>& depth, int width, int height, int k, int x, int y) {
  float result = 2.0f;
  for (int v = y << k; v < std::min((y + 1) << k, height); ++v)
    for (int u = x << k; u < std::min((x + 1) << k, width); ++u)
      result = std::min(result, depth[size_t(v) * size_t(width) + size_t(u)]);
  return result;
}

// Every texel of every level of the pyramid built on the GPU equals the brute-force minimum over its block of the
// depth, on sizes with odd edges at several levels, one level, and one that takes several dispatches.
TEST_F(GpuTest, TheDepthPyramidsEveryTexelIsTheFarthestDepthOfItsBlock) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  for (const auto& [width, height] : std::vector<std::pair<int, int>>{
           {1, 1}, {2, 1}, {37, 23}, {33, 65}, {640, 360}, {1031, 17}, {1920, 1080}}) {
    SCOPED_TRACE(testing::Message() << width << " x " << height);
    RenderTarget target(width, height);
    std::vector<float> depth(size_t(width) * size_t(height));
    // Smooth depth with holes (sky at 0) and spikes, so that minima sit anywhere in a block.
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        float d = 0.5f + 0.4f * std::sin(0.05f * float(x)) * std::cos(0.07f * float(y));
        const float r = uniform(rng);
        if (r < 0.02f) d = 0.0f;
        else if (r < 0.1f) d = uniform(rng);
        depth[size_t(y) * size_t(width) + size_t(x)] = d;
      }
    glTextureSubImage2D(target.depthTexture().handle(), 0, 0, 0, width, height, GL_DEPTH_COMPONENT, GL_FLOAT,
                        depth.data());
    GpuDepthPyramid pyramid;
    pyramid.build(target);
    const std::vector<int> sizes = pyramid.levelSizes();
    ASSERT_EQ(sizes[0], width);
    ASSERT_EQ(sizes[1], height);
    for (int k = 1; k < pyramid.levels(); ++k) {
      const int w = sizes[size_t(2 * k)], h = sizes[size_t(2 * k + 1)];
      EXPECT_EQ(w, (width + (1 << k) - 1) >> k);
      EXPECT_EQ(h, (height + (1 << k) - 1) >> k);
      GLint mip_w = 0, mip_h = 0;
      glGetTextureLevelParameteriv(pyramid.texture(), k - 1, GL_TEXTURE_WIDTH, &mip_w);
      glGetTextureLevelParameteriv(pyramid.texture(), k - 1, GL_TEXTURE_HEIGHT, &mip_h);
      ASSERT_GE(mip_w, w);
      ASSERT_GE(mip_h, h);
      std::vector<float> level(size_t(mip_w) * size_t(mip_h));
      glGetTextureImage(pyramid.texture(), k - 1, GL_RED, GL_FLOAT, GLsizei(level.size() * sizeof(float)),
                        level.data());
      int wrong = 0;
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
          wrong += level[size_t(y) * size_t(mip_w) + size_t(x)] != bruteTexel(depth, width, height, k, x, y);
      EXPECT_EQ(wrong, 0) << "level " << k << " (" << w << " x " << h << ")";
    }
  }
}

}  // namespace
}  // namespace farfield::gpu
