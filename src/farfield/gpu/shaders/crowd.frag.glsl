#version 450 core
// Farfield crowd fragment shader for skinned agents: albedo = base colour * texture * agent tint * the tint of the
// triangle's colour region in the agent's outfit (regions per triangle at binding 3, indexed by gl_PrimitiveID;
// tints at binding 2: outfit o's region r at (o mod u_outfits) * 16 + r); with FF_CUTOUT, texels with alpha below 0.5
// cut out. Lit as mesh.frag.glsl: albedo * (ambient + light_color * max(dot(n, -light_dir), 0)).
// FF_CAPTURE (multi-view impostor bake): attachment 0 = the untinted albedo, its alpha coding the colour region r as
// (16 (r + 1) - 1) / 255 (coverage: alpha >= 8/255); attachment 1 = the normal (agent space, 0.5 n + 0.5) and in
// alpha the depth along u_capture_dir from u_capture_centre over u_capture_radius (0.5 d + 0.5).
// FF_DEPTH_ONLY (shadow casters): no colour.
// FF_CUTOUT: texels with alpha below 0.5 are cut out (discard). Left out for models that have none
// (gpu::SkinnedGpuModel::cutout), so that the depth test can run before the shader.

in vec3 v_world;
in vec3 v_normal;
in vec2 v_uv;
flat in vec4 v_tint;
flat in uint v_id;
flat in uint v_outfit;

#ifdef FF_CAPTURE
layout(location = 0) out vec4 o_color;
layout(location = 1) out vec4 o_normal_depth;
uniform vec3 u_capture_dir;  // unit, towards the capture camera
uniform vec3 u_capture_centre;
uniform float u_capture_radius;
#elif !defined(FF_DEPTH_ONLY)
layout(location = 0) out vec4 o_color;
layout(location = 1) out uint o_id;
uniform vec3 u_light_dir;
uniform vec3 u_light_color;
uniform float u_ambient;
layout(std430, binding = 2) readonly buffer Tints { vec4 tints[]; };
uniform uint u_outfits;
#endif

layout(std430, binding = 3) readonly buffer Regions { uint regions[]; };
uniform uint u_first_triangle;  // the drawn level's first triangle in regions (SkinnedGpuModel)
uniform vec4 u_base_color;
uniform int u_textured;
layout(binding = 0) uniform sampler2D u_texture;

void main() {
  vec4 albedo = u_base_color;
  if (u_textured != 0) albedo *= texture(u_texture, v_uv);
#ifdef FF_CUTOUT
  if (albedo.a < 0.5) discard;
#endif
#ifndef FF_DEPTH_ONLY
  const uint region = regions[u_first_triangle + uint(gl_PrimitiveID)];
  vec3 n = v_normal;
  if (dot(n, n) < 1e-12) n = cross(dFdx(v_world), dFdy(v_world));
  n = normalize(n);
#ifdef FF_CAPTURE
  o_color = vec4(albedo.rgb, float(16u * (region + 1u) - 1u) / 255.0);
  const float d = dot(v_world - u_capture_centre, u_capture_dir) / u_capture_radius;
  o_normal_depth = vec4(0.5 * n + 0.5, clamp(0.5 * d + 0.5, 0.0, 1.0));
#else
  albedo *= v_tint * tints[(v_outfit % u_outfits) * 16u + region];
  o_color = vec4(albedo.rgb * (vec3(u_ambient) + u_light_color * max(dot(n, -u_light_dir), 0.0)), albedo.a);
  o_id = v_id;
#endif
#endif
}
