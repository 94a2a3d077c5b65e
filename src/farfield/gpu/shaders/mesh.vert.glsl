#version 450 core
// Farfield mesh vertex shader: world-space position, normal and uv for mesh.frag.glsl.
// Variants (defines inserted by the renderer): FF_ITEM_BUFFER (ids only), FF_TEXTURED (samples u_texture).

layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv;

uniform mat4 u_view_proj;
uniform mat4 u_model;
uniform mat3 u_normal_matrix;  // inverse transpose of the model matrix's 3x3 part
uniform mat4 u_texture_projection;  // projective texturing (GpuMaterial::projective_texture)

// gl_Position is invariant: GLSL guarantees the same position from the same inputs only across programs that declare
// it so; otherwise a driver may compile the same expression differently in two programs (fused multiply-adds).
// (arena.vert.glsl draws the same objects; each variant here draws them in the reference and the item buffers.)
invariant gl_Position;

out vec3 v_world;
out vec3 v_normal;
out vec2 v_uv;
out vec4 v_uv_projected;  // homogeneous texture coordinate for projective texturing

void main() {
  vec4 world = u_model * vec4(a_position, 1.0);
  v_world = world.xyz;
  v_normal = u_normal_matrix * a_normal;
  v_uv = a_uv;
  v_uv_projected = u_texture_projection * vec4(a_position, 1.0);  // object space: sticks to the mesh
  gl_Position = u_view_proj * world;
}
