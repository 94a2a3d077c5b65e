#version 450 core
// Farfield arena vertex shader (gpu/scene_arena.h): mesh.vert.glsl's outputs for a cluster drawn by a multi-draw,
// whose part (its object's transform and normal matrix, its material) comes per instance from the part's row, picked
// by the draw's baseInstance (vertex attributes read once per draw, not a storage-buffer lookup per vertex).
// The same arithmetic as mesh.vert.glsl, so that a cluster lands on the pixels and depths its object's draw gives.

layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv;
layout(location = 3) in vec4 a_model0;  // the object's transform, by columns
layout(location = 4) in vec4 a_model1;
layout(location = 5) in vec4 a_model2;
layout(location = 6) in vec4 a_model3;
layout(location = 7) in vec4 a_normal0;  // its normal matrix's columns (xyz)
layout(location = 8) in vec4 a_normal1;
layout(location = 9) in vec4 a_normal2;
layout(location = 10) in vec4 a_base_color;
layout(location = 11) in uvec4 a_info;  // object id, unlit, texture layer

uniform mat4 u_view_proj;

// gl_Position is invariant: GLSL guarantees the same position from the same inputs only across programs that declare
// it so; otherwise a driver may compile the same expression differently in two programs (fused multiply-adds).
// The frustum-culled frame draws the same objects through mesh.vert.glsl: cull-check wants equal ids at every pixel.
invariant gl_Position;

out vec3 v_world;
out vec3 v_normal;
out vec2 v_uv;
out vec4 v_uv_projected;  // unused here; mesh.frag.glsl declares it
flat out uint v_object_id;
flat out vec4 v_base_color;
flat out uint v_unlit;
flat out uint v_layer;

void main() {
  const mat4 model = mat4(a_model0, a_model1, a_model2, a_model3);
  vec4 world = model * vec4(a_position, 1.0);
  v_world = world.xyz;
  v_normal = mat3(a_normal0.xyz, a_normal1.xyz, a_normal2.xyz) * a_normal;
  v_uv = a_uv;
  v_uv_projected = vec4(0.0);
  v_object_id = a_info.x;
  v_base_color = a_base_color;
  v_unlit = a_info.y;
  v_layer = a_info.z;
  gl_Position = u_view_proj * world;
}
