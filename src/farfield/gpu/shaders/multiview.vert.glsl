#version 450 core
// Farfield multi-view impostor (Tecchia, Loscos and Chrysanthou's crowd; Steed's lecture part 3): one instanced
// camera-facing quad per agent, spanning the model's capture extent (u_half_size metres right and up) around its
// centre, showing the atlas cell of the agent's view (data.y) and animation frame (data.x, the array layer).
// Drawn as a 4-vertex triangle strip per instance, no vertex buffer. With u_fixed_dir non-zero (an orthographic
// light: shadow casters) every quad faces that unit direction instead of the eye.

struct Agent {
  vec4 pos_heading;
  vec4 tint;
  uvec4 data;  // x: frame (layer), y: view (elevation * azimuths + azimuth), z: object id, w: outfit
};
layout(std430, binding = 1) readonly buffer Agents { Agent agents[]; };

uniform mat4 u_view_proj;
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
  gl_Position = u_view_proj * vec4(v_world, 1.0);
}
