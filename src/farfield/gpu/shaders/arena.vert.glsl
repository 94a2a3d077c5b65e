#version 450 core
// Farfield arena vertex shader (gpu/scene_arena.h): mesh.vert.glsl's outputs for a cluster drawn by a multi-draw,
// whose instance (its object, its material) comes from the draw's baseInstance through a per-instance attribute.
// The same arithmetic as mesh.vert.glsl, so that a cluster lands on the pixels and depths its object's draw gives.

layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv;
layout(location = 3) in uint a_instance;

struct Object {
  mat4 model;
  mat4 normal_matrix;  // mat3 in the first three columns
  vec4 misc;
  uvec4 info;          // id, flags
};
struct Material {
  vec4 base_color;
  uvec4 info;  // unlit, texture layer
};
layout(std430, binding = 1) readonly buffer Instances { uvec4 instances[]; };
layout(std430, binding = 2) readonly buffer Objects { Object objects[]; };
layout(std430, binding = 3) readonly buffer Materials { Material materials[]; };

uniform mat4 u_view_proj;

out vec3 v_world;
out vec3 v_normal;
out vec2 v_uv;
out vec4 v_uv_projected;  // unused here; mesh.frag.glsl declares it
flat out uint v_object_id;
flat out vec4 v_base_color;
flat out uint v_unlit;
flat out uint v_layer;

void main() {
  const uvec4 instance = instances[a_instance];
  const mat4 model = objects[instance.y].model;
  vec4 world = model * vec4(a_position, 1.0);
  v_world = world.xyz;
  v_normal = mat3(objects[instance.y].normal_matrix) * a_normal;
  v_uv = a_uv;
  v_uv_projected = vec4(0.0);
  v_object_id = objects[instance.y].info.x;
  v_base_color = materials[instance.z].base_color;
  v_unlit = materials[instance.z].info.x;
  v_layer = materials[instance.z].info.y;
  gl_Position = u_view_proj * world;
}
