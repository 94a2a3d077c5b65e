#version 450 core
// Farfield multi-view impostor (Tecchia, Loscos and Chrysanthou's crowd; Steed's lecture part 3): one instanced
// camera-facing quad per agent, spanning the model's capture extent (u_half_size metres right and up) around its
// centre, showing the atlas cell of the agent's view (data.y) and animation frame (data.x, the array layer).
// Drawn as a 4-vertex triangle strip per instance, no vertex buffer. With u_fixed_dir non-zero (an orthographic
// light: shadow casters) every quad faces that unit direction instead of the eye. FF_BLEND_VIEWS: the four views
// around the direction to the eye (two azimuths on the two elevation rings around it) with bilinear weights in
// azimuth and elevation, for the fragment shader to blend (the agent's own `view` is then unused); on an octahedral
// grid (u_octahedral) the four corners of the map square holding the direction's octahedral point (impostor::
// octahedralPoint), weighted bilinearly in the map.

struct Agent {
  vec4 pos_heading;
  vec4 tint;
  uvec4 data;  // x: frame (layer), y: view (elevation * azimuths + azimuth), z: object id, w: outfit
};
layout(std430, binding = 1) readonly buffer Agents { Agent agents[]; };

uniform mat4 u_view_proj;
// gl_Position is invariant: GLSL guarantees the same position from the same inputs only across programs that declare
// it so; otherwise a driver may compile the same expression differently in two programs (fused multiply-adds).
// (the CPU and GPU crowd paths draw the same impostors through variants of this shader.)
invariant gl_Position;
uniform vec3 u_eye;
uniform vec3 u_fixed_dir;
uniform vec2 u_half_size;
uniform vec3 u_centre;  // the model's capture centre in agent space
uniform uint u_first_instance;

out vec2 v_cell_uv;  // [0,1]^2 across the quad, v up
out vec3 v_world;
flat out vec3 v_to_eye;
flat out vec4 v_tint;
flat out uvec4 v_data;
flat out float v_heading;
#ifdef FF_BLEND_VIEWS
uniform ivec2 u_grid;  // azimuths, elevations
uniform float u_max_elevation;
uniform int u_octahedral;
flat out uvec4 v_views;
flat out vec4 v_weights;
#endif

void main() {
  const Agent a = agents[u_first_instance + uint(gl_InstanceID)];
  const vec2 corner = vec2(float(gl_VertexID & 1) * 2.0 - 1.0, float((gl_VertexID >> 1) & 1) * 2.0 - 1.0);
  const float c = cos(a.pos_heading.w), s = sin(a.pos_heading.w);
  const vec3 centre = a.pos_heading.xyz + vec3(c * u_centre.x - s * u_centre.y, s * u_centre.x + c * u_centre.y,
                                               u_centre.z);
  const vec3 d = dot(u_fixed_dir, u_fixed_dir) > 0.0 ? u_fixed_dir : normalize(u_eye - centre);
  vec3 right = cross(vec3(0.0, 0.0, 1.0), d);
  right = dot(right, right) < 1e-8 ? vec3(c, s, 0.0) : normalize(right);
  const vec3 up = cross(d, right);
  v_world = centre + corner.x * u_half_size.x * right + corner.y * u_half_size.y * up;
  v_cell_uv = 0.5 * corner + 0.5;
  v_to_eye = d;
  v_tint = a.tint;
  v_data = a.data;
  v_heading = a.pos_heading.w;
#ifdef FF_BLEND_VIEWS
  const vec3 local = vec3(c * d.x + s * d.y, -s * d.x + c * d.y, d.z);  // towards the eye, agent space
  // The four views: columns c0, c1 and rows r0, r1 of the grid around the direction, fractions tc and tr between them.
  int c0, c1, r0, r1;
  float tc, tr;
  if (u_octahedral != 0) {
    const vec3 h = vec3(local.xy, max(local.z, 0.0));
    const vec2 p = h.xy / max(abs(h.x) + abs(h.y) + h.z, 1e-8);
    const vec2 f = (vec2(p.x + p.y, p.x - p.y) * 0.5 + 0.5) * float(u_grid.x - 1);
    const ivec2 i0 = clamp(ivec2(floor(f)), ivec2(0), ivec2(u_grid.x - 2));
    const vec2 t = clamp(f - vec2(i0), 0.0, 1.0);
    c0 = i0.x, c1 = i0.x + 1, r0 = i0.y, r1 = i0.y + 1, tc = t.x, tr = t.y;
  } else {
    float az = atan(local.y, local.x);
    if (az < 0.0) az += 6.28318530718;
    const float fa = az / 6.28318530718 * float(u_grid.x);
    c0 = int(floor(fa)) % u_grid.x, c1 = (c0 + 1) % u_grid.x, tc = fract(fa);
    const float fe = clamp(asin(clamp(local.z, -1.0, 1.0)) / (u_max_elevation / float(u_grid.y)), 0.0,
                           float(u_grid.y - 1));
    r0 = min(int(floor(fe)), u_grid.y - 1), r1 = min(r0 + 1, u_grid.y - 1), tr = fe - float(r0);
  }
  v_views = uvec4(r0 * u_grid.x + c0, r0 * u_grid.x + c1, r1 * u_grid.x + c0, r1 * u_grid.x + c1);
  v_weights = vec4((1.0 - tc) * (1.0 - tr), tc * (1.0 - tr), (1.0 - tc) * tr, tc * tr);
#endif
  gl_Position = u_view_proj * vec4(v_world, 1.0);
}
