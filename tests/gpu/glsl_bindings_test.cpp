// What the barrier check reads from a shader (gpu/glsl_bindings.h): its bindings, which of them it may write, and
// only the lines its preprocessor keeps.
#include "farfield/gpu/glsl_bindings.h"

#include <gtest/gtest.h>

namespace farfield::gpu {
namespace {

TEST(GlslBindings, ReadsBindingsQualifiersAndTheConditionalsTheSourceDefines) {
  const GlslBindings b = glslBindings(R"(#version 450 core
#define FF_STAGE_A 1
#define FF_LEVEL 2
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer In { uint a[]; };   // read only
layout(std430, binding = 1) buffer Out { uint b[]; };
// layout(std430, binding = 9) buffer Commented { uint c[]; };
/* layout(std430, binding = 10) buffer Commented2 { uint d[]; }; */
#ifdef FF_STAGE_A
layout(std430, binding = 2) coherent buffer InA { uint e[]; };
#else
layout(std430, binding = 3) buffer NotA { uint f[]; };
#endif
#if defined(FF_STAGE_B) || !defined(FF_STAGE_A)
layout(std430, binding = 4) buffer B { uint g[]; };
#elif FF_LEVEL >= 2 && defined FF_STAGE_A
layout(std430, binding = 5) readonly buffer Level { uint h[]; };
#endif
#ifndef FF_STAGE_A
#define FF_HIDDEN 1
#endif
#ifdef FF_HIDDEN
layout(std430, binding = 6) buffer Hidden { uint i[]; };
#endif
layout(r32f, binding = 0) readonly uniform image2D u_src;
layout(r32f, binding = 1) writeonly uniform image2D u_dst;
layout(binding = 3) uniform sampler2D u_depth;
layout(binding = 4) uniform usampler2DArray u_ids;
void main() {}
)");
  EXPECT_EQ(b.buffers, (std::set<int>{0, 1, 2, 5}));
  EXPECT_EQ(b.written_buffers, (std::set<int>{1, 2}));
  EXPECT_EQ(b.images, (std::set<int>{0, 1}));
  EXPECT_EQ(b.written_images, (std::set<int>{1}));
  EXPECT_EQ(b.samplers, (std::set<int>{3, 4}));
}

}  // namespace
}  // namespace farfield::gpu
