#version 450 core
// Farfield terrain vertex shader (gpu/terrain_renderer.h): grid positions in the terrain's world frame; the
// original texture's uv from world xy; with FF_SPRITE the sprite camera's clip position for projective texturing.

layout(location = 0) in vec3 a_position;

uniform mat4 u_view_proj;
uniform vec2 u_uv_scale;
uniform vec2 u_uv_offset;
#ifdef FF_SPRITE
uniform mat4 u_sprite_view_proj;
out vec4 v_sprite_clip;
#else
out vec2 v_uv;
#endif

void main() {
#ifdef FF_SPRITE
  v_sprite_clip = u_sprite_view_proj * vec4(a_position, 1.0);
#else
  v_uv = a_position.xy * u_uv_scale + u_uv_offset;
#endif
  gl_Position = u_view_proj * vec4(a_position, 1.0);
}
