#version 450 core
// Farfield instanced skinning: one draw per model draws every agent of it. Joint matrices of a palette of sampled
// poses (binding 0, pose p's joint j at p * u_joint_count + j); per agent (binding 1): position and heading (radians
// about +z), a colour tint, its pose, object id and outfit (a row of the colour-region tints crowd.frag.glsl reads).
// world = agent(heading, position) * u_model_to_agent * skin * p.
// FF_BAKED_POSES (gpu::Skinning::BakedPoses): binding 0 holds every pose's vertices already skinned, pose p's vertex
// i (position, normal) at p * u_vertex_count + i, and the joint attributes are not read.

layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv;
layout(location = 3) in uvec4 a_joints;
layout(location = 4) in vec4 a_weights;

struct Agent {
  vec4 pos_heading;
  vec4 tint;
  uvec4 data;  // x: pose (palette index), y: unused here, z: object id, w: outfit
};
#ifdef FF_BAKED_POSES
struct BakedVertex {
  vec4 position;
  vec4 normal;
};
layout(std430, binding = 0) readonly buffer Baked { BakedVertex baked[]; };
uniform uint u_vertex_count;
#else
layout(std430, binding = 0) readonly buffer Palette { mat4 palette[]; };
uniform uint u_joint_count;
#endif
layout(std430, binding = 1) readonly buffer Agents { Agent agents[]; };

uniform mat4 u_view_proj;
// gl_Position is invariant: GLSL guarantees the same position from the same inputs only across programs that declare
// it so; otherwise a driver may compile the same expression differently in two programs (fused multiply-adds).
// (the CPU and GPU crowd paths, and the reference, draw the same agents through variants of this shader.)
invariant gl_Position;
uniform mat4 u_model_to_agent;
uniform uint u_first_instance;

out vec3 v_world;
out vec3 v_normal;
out vec2 v_uv;
flat out vec4 v_tint;
flat out uint v_id;
flat out uint v_outfit;

void main() {
  const Agent a = agents[u_first_instance + uint(gl_InstanceID)];
#ifdef FF_BAKED_POSES
  const BakedVertex posed = baked[a.data.x * u_vertex_count + uint(gl_VertexID)];
  const vec3 skinned_position = posed.position.xyz, skinned_normal = posed.normal.xyz;
#else
  const uint base = a.data.x * u_joint_count;
  const mat4 skin = a_weights.x * palette[base + a_joints.x] + a_weights.y * palette[base + a_joints.y] +
                    a_weights.z * palette[base + a_joints.z] + a_weights.w * palette[base + a_joints.w];
  const vec3 skinned_position = (skin * vec4(a_position, 1.0)).xyz, skinned_normal = mat3(skin) * a_normal;
#endif
  const vec4 local = u_model_to_agent * vec4(skinned_position, 1.0);
  const float c = cos(a.pos_heading.w), s = sin(a.pos_heading.w);
  const mat3 turn = mat3(c, s, 0.0, -s, c, 0.0, 0.0, 0.0, 1.0);
  v_world = turn * local.xyz + a.pos_heading.xyz;
  v_normal = turn * (mat3(u_model_to_agent) * skinned_normal);
  v_uv = a_uv;
  v_tint = a.tint;
  v_id = a.data.z;
  v_outfit = a.data.w;
  gl_Position = u_view_proj * vec4(v_world, 1.0);
}
