#version 450 core
// A smaller target's frame over the whole of this one (gpu/target_upscaler.h): colour bilinear, object id (with
// FF_UPSCALE_IDS) and depth (with FF_UPSCALE_DEPTH) from the nearest texel, as glBlitFramebuffer's GL_LINEAR and
// GL_NEAREST take them.
layout(binding = 0) uniform sampler2D u_color;   // linear filter, clamped to the edge
layout(binding = 1) uniform usampler2D u_ids;
layout(binding = 2) uniform sampler2D u_depth;
uniform vec2 u_from_per_to;  // source pixels per target pixel, per axis
uniform ivec2 u_from_size;

layout(location = 0) out vec4 o_color;
#ifdef FF_UPSCALE_IDS
layout(location = 1) out uint o_id;
#endif

void main() {
  const vec2 at = gl_FragCoord.xy * u_from_per_to;  // the target pixel's centre in source pixels
  const ivec2 nearest = min(ivec2(at), u_from_size - 1);
  o_color = texture(u_color, at / vec2(u_from_size));
#ifdef FF_UPSCALE_IDS
  o_id = texelFetch(u_ids, nearest, 0).r;
#endif
#ifdef FF_UPSCALE_DEPTH
  gl_FragDepth = texelFetch(u_depth, nearest, 0).r;
#endif
}
