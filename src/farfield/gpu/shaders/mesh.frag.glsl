#version 450 core
// Farfield mesh fragment shader: colour to attachment 0, object id to attachment 1 (R32UI).
// Shaded: lit colour = albedo * (ambient + light_color * max(dot(n, -light_dir), 0)), unlit colour = albedo, where
// albedo = base colour (times the texture with FF_TEXTURED, texels with alpha < 0.5 are cut out). With FF_TEXTURED
// and u_has_ids, the id is the texel's of u_ids at the same texture coordinate (impostors: per-pixel object ids).
// FF_ITEM_BUFFER: a flat false colour of the object id, no texture sampling.
// FF_ARENA (arena.vert.glsl): object id, base colour, unlit flag and texture layer come per draw from the vertex
// shader instead of uniforms, and FF_TEXTURED samples the layer of a texture array; no projective texturing, no ids.

in vec3 v_world;
in vec3 v_normal;
in vec2 v_uv;
in vec4 v_uv_projected;

layout(location = 0) out vec4 o_color;
layout(location = 1) out uint o_id;

#ifdef FF_ARENA
flat in uint v_object_id;
flat in vec4 v_base_color;
flat in uint v_unlit;
flat in uint v_layer;
#define OBJECT_ID v_object_id
#else
uniform uint u_object_id;
#define OBJECT_ID u_object_id
#endif

#ifdef FF_ITEM_BUFFER

void main() {
  uint h = OBJECT_ID * 2654435761u;
  o_color = OBJECT_ID == 0u ? vec4(0.0, 0.0, 0.0, 1.0)
                            : vec4(float((h >> 24) & 255u), float((h >> 16) & 255u), float((h >> 8) & 255u), 255.0) / 255.0;
  o_id = OBJECT_ID;
}

#else

uniform vec3 u_light_dir;  // direction the light travels, unit length
uniform vec3 u_light_color;
uniform float u_ambient;
#ifdef FF_ARENA
#define BASE_COLOR v_base_color
#define UNLIT int(v_unlit)
#ifdef FF_TEXTURED
layout(binding = 0) uniform sampler2DArray u_texture;
#endif
#else
uniform vec4 u_base_color;
uniform int u_unlit;
uniform int u_projective_texture;  // 1: texture coordinate = v_uv_projected.xy / v_uv_projected.w
#define BASE_COLOR u_base_color
#define UNLIT u_unlit
#ifdef FF_TEXTURED
layout(binding = 0) uniform sampler2D u_texture;
uniform int u_has_ids;  // 1: object ids per texel in u_ids (0 texels keep u_object_id)
layout(binding = 1) uniform usampler2D u_ids;
#endif
#endif

void main() {
  vec4 albedo = BASE_COLOR;
#ifdef FF_TEXTURED
#ifdef FF_ARENA
  const vec2 uv = v_uv;
  albedo *= texture(u_texture, vec3(uv, float(v_layer)));
#else
  const vec2 uv = u_projective_texture != 0 ? v_uv_projected.xy / v_uv_projected.w : v_uv;
  albedo *= texture(u_texture, uv);
#endif
  if (albedo.a < 0.5) discard;
#endif
  uint id = OBJECT_ID;
#if defined(FF_TEXTURED) && !defined(FF_ARENA)
  if (u_has_ids != 0) {
    const ivec2 size = textureSize(u_ids, 0);
    const uint texel = texelFetch(u_ids, clamp(ivec2(floor(uv * vec2(size))), ivec2(0), size - 1), 0).r;
    if (texel != 0u) id = texel;
  }
#endif
  vec3 rgb = albedo.rgb;
  if (UNLIT == 0) {
    vec3 n = v_normal;
    if (dot(n, n) < 1e-12) {
      // No vertex normal: the face normal from screen-space derivatives, which always faces the viewer.
      n = cross(dFdx(v_world), dFdy(v_world));
    } else if (!gl_FrontFacing) {
      n = -n;  // back face of a double-sided surface
    }
    n = normalize(n);
    rgb *= vec3(u_ambient) + u_light_color * max(dot(n, -u_light_dir), 0.0);
  }
  o_color = vec4(rgb, albedo.a);
  o_id = id;
}

#endif
