#version 450 core
// Farfield depth pyramid (gpu/gpu_culler.h): level k + 1 from level k, each texel the farthest (smallest, reversed Z)
// of the 2 x 2 texels below it, clamped at odd edges: gpu::DepthPyramid::build on the GPU. Level 0 is the frame's
// depth texture; levels 1.. are the mip levels 0.. of one R32F texture.

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 2) uniform sampler2D u_depth;
layout(r32f, binding = 0) readonly uniform image2D u_src;   // level k when k >= 1
layout(r32f, binding = 1) writeonly uniform image2D u_dst;  // level k + 1

uniform ivec2 u_src_size;
uniform ivec2 u_dst_size;
uniform int u_from_depth;

float source(ivec2 p) { return u_from_depth != 0 ? texelFetch(u_depth, p, 0).r : imageLoad(u_src, p).r; }

void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= u_dst_size.x || p.y >= u_dst_size.y) return;
  const ivec2 a = 2 * p;
  const ivec2 b = min(a + 1, u_src_size - 1);
  const float d = min(min(source(a), source(ivec2(b.x, a.y))), min(source(ivec2(a.x, b.y)), source(b)));
  imageStore(u_dst, p, vec4(d));
}
