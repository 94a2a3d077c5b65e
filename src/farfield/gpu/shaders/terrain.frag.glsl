#version 450 core
// Farfield terrain fragment shader (gpu/terrain_renderer.h), unlit: the original texture, or with FF_SPRITE the
// sprite (an earlier frame) projected through the sprite camera: the clip position is interpolated perspective-
// correctly and divided per fragment, so a point of the surface samples the sprite where the sprite camera saw it.
// With FF_CDLOD_SPRITE (the CDLOD terrain's LOD-sprite frame, cdlod.vert.glsl with FF_CDLOD_SPRITE): the sprite,
// projected as with FF_SPRITE, where the fragment's triangle has its three vertices visible in the keyframe (v_hidden
// interpolates to 0 only there), the original texture elsewhere (a paged terrain's page colours), in one draw.
// With FF_HOLE (the CDLOD terrain, gpu/cdlod_renderer.h), fragments inside a rectangle of world x, y are left out.

layout(location = 0) out vec4 o_color;
layout(location = 1) out uint o_id;

uniform uint u_object_id;
layout(binding = 0) uniform sampler2D u_texture;
#ifdef FF_SPRITE
in vec4 v_sprite_clip;
#else
in vec2 v_uv;
#endif
#ifdef FF_CDLOD_SPRITE
in vec4 v_sprite_clip;
in float v_hidden;
layout(binding = 5) uniform sampler2D u_sprite;
#endif
#ifdef FF_PAGED
// A paged CDLOD terrain (gpu/cdlod_pages.h): fragments of nodes read from a page take its colour layer.
flat in int v_layer;
layout(binding = 3) uniform sampler2DArray u_page_colours;
#endif
#ifdef FF_HOLE
// A rectangle of the ground (world x, y: lo, hi) drawn by someone else (a city), left out.
in vec2 v_world_xy;
uniform vec4 u_hole;
#endif

#ifndef FF_SPRITE
// The original texture at the fragment: a paged terrain's page colours where its node reads a page.
vec3 originalColour() {
#ifdef FF_PAGED
  if (v_layer >= 0) return texture(u_page_colours, vec3(v_uv, float(v_layer))).rgb;
#endif
  return texture(u_texture, v_uv).rgb;
}
#endif

void main() {
#ifdef FF_HOLE
  if (all(greaterThan(v_world_xy, u_hole.xy)) && all(lessThan(v_world_xy, u_hole.zw))) discard;
#endif
#if defined(FF_CDLOD_SPRITE)
  if (v_hidden < 0.5) {
    vec2 st = v_sprite_clip.xy / v_sprite_clip.w * 0.5 + 0.5;
    o_color = vec4(texture(u_sprite, st).rgb, 1.0);
  } else {
    o_color = vec4(originalColour(), 1.0);
  }
#elif defined(FF_SPRITE)
  vec2 st = v_sprite_clip.xy / v_sprite_clip.w * 0.5 + 0.5;
  o_color = vec4(texture(u_texture, st).rgb, 1.0);
#else
  o_color = vec4(originalColour(), 1.0);
#endif
  o_id = u_object_id;
}
