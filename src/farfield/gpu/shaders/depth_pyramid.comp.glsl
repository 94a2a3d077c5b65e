#version 450 core
// Farfield depth pyramid (gpu/gpu_depth_pyramid.h): up to three levels per dispatch, each texel the farthest
// (smallest, reversed Z) of the 2 x 2 texels of the level below, clamped at odd edges: gpu::DepthPyramid::build on
// the GPU. Level 0 is the frame's depth texture; levels 1.. are the mip levels 0.. of one R32F texture.
//
// An invocation makes one texel of level u_first + u_count and every texel below it down to level u_first + 1: a
// block of 2^(u_count - 1) texels a side at level u_first + 1 from the clamped texels of level u_first, then halved in
// registers, level by level. A texel's children lie in its own block; a child beyond its level's size reads the
// clamped texels at the edge, which its sibling inside the level covers too, so it never changes its parent's
// minimum, and it is never stored. No shared memory and no barrier: on a software rasterizer a barrier switches
// every invocation of a work group, which made a 16 x 16 tile reduced in shared memory slower than one dispatch a
// level.

layout(local_size_x = 8, local_size_y = 8) in;

const int kMaxSide = 4;  // the block's side at level u_first + 1: u_count at most 3

layout(binding = 2) uniform sampler2D u_depth;
layout(r32f, binding = 0) readonly uniform image2D u_src;  // level u_first when u_first >= 1
layout(r32f, binding = 1) writeonly uniform image2D u_dst1;  // levels u_first + 1 ..
layout(r32f, binding = 2) writeonly uniform image2D u_dst2;
layout(r32f, binding = 3) writeonly uniform image2D u_dst3;

uniform int u_first;       // the level read
uniform int u_count;       // levels made: 1..3
uniform ivec2 u_size[16];  // every level's size, level 0 first

float source(ivec2 p) { return u_first == 0 ? texelFetch(u_depth, p, 0).r : imageLoad(u_src, p).r; }

void store(int j, ivec2 p, float d) {  // level u_first + j
  if (any(greaterThanEqual(p, u_size[u_first + j]))) return;
  if (j == 1) imageStore(u_dst1, p, vec4(d));
  else if (j == 2) imageStore(u_dst2, p, vec4(d));
  else imageStore(u_dst3, p, vec4(d));
}

void main() {
  const ivec2 t = ivec2(gl_GlobalInvocationID.xy);  // the texel of level u_first + u_count
  if (any(greaterThanEqual(t, u_size[u_first + u_count]))) return;
  int side = 1 << (u_count - 1);
  ivec2 origin = t * side;  // the block's first texel at level u_first + 1
  const ivec2 last = u_size[u_first] - 1;
  float v[kMaxSide * kMaxSide];
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) {
      const ivec2 p = origin + ivec2(x, y);
      const ivec2 a = min(2 * p, last), b = min(2 * p + 1, last);
      const float d = min(min(source(a), source(ivec2(b.x, a.y))), min(source(ivec2(a.x, b.y)), source(b)));
      v[y * kMaxSide + x] = d;
      store(1, p, d);
    }
  for (int j = 2; j <= u_count; ++j) {
    // In place: texel (x, y) is written after its children (2x.., 2y..), which no later texel reads.
    side >>= 1;
    origin >>= 1;
    for (int y = 0; y < side; ++y)
      for (int x = 0; x < side; ++x) {
        const int c = 2 * y * kMaxSide + 2 * x;
        const float d = min(min(v[c], v[c + 1]), min(v[c + kMaxSide], v[c + kMaxSide + 1]));
        v[y * kMaxSide + x] = d;
        store(j, origin + ivec2(x, y), d);
      }
  }
}
