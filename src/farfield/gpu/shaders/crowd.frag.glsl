#version 450 core
// Farfield crowd fragment shader for skinned agents: albedo = base colour * texture * agent tint (texels with alpha
// below 0.5 cut out), lit as mesh.frag.glsl: albedo * (ambient + light_color * max(dot(n, -light_dir), 0)).
// FF_CAPTURE (multi-view impostor bake): attachment 0 = albedo with alpha 1, attachment 1 = the normal (agent space,
// 0.5 n + 0.5) and in alpha the depth along u_capture_dir from u_capture_centre over u_capture_radius (0.5 d + 0.5).

in vec3 v_world;
in vec3 v_normal;
in vec2 v_uv;
flat in vec4 v_tint;
flat in uint v_id;

layout(location = 0) out vec4 o_color;
#ifdef FF_CAPTURE
layout(location = 1) out vec4 o_normal_depth;
uniform vec3 u_capture_dir;  // unit, towards the capture camera
uniform vec3 u_capture_centre;
uniform float u_capture_radius;
#else
layout(location = 1) out uint o_id;
uniform vec3 u_light_dir;
uniform vec3 u_light_color;
uniform float u_ambient;
#endif

uniform vec4 u_base_color;
uniform int u_textured;
layout(binding = 0) uniform sampler2D u_texture;

void main() {
  vec4 albedo = u_base_color * v_tint;
  if (u_textured != 0) albedo *= texture(u_texture, v_uv);
  if (albedo.a < 0.5) discard;
  vec3 n = v_normal;
  if (dot(n, n) < 1e-12) n = cross(dFdx(v_world), dFdy(v_world));
  n = normalize(n);
#ifdef FF_CAPTURE
  o_color = vec4(albedo.rgb, 1.0);
  const float d = dot(v_world - u_capture_centre, u_capture_dir) / u_capture_radius;
  o_normal_depth = vec4(0.5 * n + 0.5, clamp(0.5 * d + 0.5, 0.0, 1.0));
#else
  o_color = vec4(albedo.rgb * (vec3(u_ambient) + u_light_color * max(dot(n, -u_light_dir), 0.0)), albedo.a);
  o_id = v_id;
#endif
}
