#version 450 core
// Farfield multi-view impostor fragment: the atlas cell's albedo (alpha < 0.5 cut out) times the agent's tint, lit
// from the baked normal turned by the agent's heading (as crowd.frag.glsl lights the geometry); the depth moved
// from the quad along the view by the baked depth, so agents intersect the scene and each other per texel.

in vec2 v_cell_uv;
in vec3 v_world;
flat in vec3 v_to_eye;
flat in vec4 v_tint;
flat in uvec3 v_data;
flat in float v_heading;

layout(location = 0) out vec4 o_color;
layout(location = 1) out uint o_id;

layout(binding = 0) uniform sampler2DArray u_albedo;
layout(binding = 1) uniform sampler2DArray u_normal_depth;
uniform ivec2 u_grid;  // azimuths, elevations
uniform float u_radius;
uniform mat4 u_view_proj;
uniform vec3 u_light_dir;
uniform vec3 u_light_color;
uniform float u_ambient;

void main() {
  const int view = int(v_data.y);
  const vec2 cell = vec2(float(view % u_grid.x), float(view / u_grid.x));
  const vec3 uvw = vec3((cell + v_cell_uv) / vec2(u_grid), float(v_data.x));
  const vec4 albedo = texture(u_albedo, uvw) * v_tint;
  if (albedo.a < 0.5) discard;
  const vec4 nd = texture(u_normal_depth, uvw);
  const vec3 nl = nd.xyz * 2.0 - 1.0;
  const float c = cos(v_heading), s = sin(v_heading);
  vec3 n = vec3(c * nl.x - s * nl.y, s * nl.x + c * nl.y, nl.z);
  n = dot(n, n) > 1e-8 ? normalize(n) : v_to_eye;
  const vec3 world = v_world + v_to_eye * ((nd.w * 2.0 - 1.0) * u_radius);
  const vec4 clip = u_view_proj * vec4(world, 1.0);
  gl_FragDepth = clip.z / clip.w;
  o_color = vec4(albedo.rgb * (vec3(u_ambient) + u_light_color * max(dot(n, -u_light_dir), 0.0)), 1.0);
  o_id = v_data.z;
}
