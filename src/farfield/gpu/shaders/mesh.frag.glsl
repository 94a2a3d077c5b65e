#version 450 core
// Farfield mesh fragment shader: colour to attachment 0, object id to attachment 1 (R32UI).
// Shaded: lit colour = albedo * (ambient + light_color * max(dot(n, -light_dir), 0)), unlit colour = albedo, where
// albedo = base colour (times the texture with FF_TEXTURED, texels with alpha < 0.5 are cut out). With FF_TEXTURED
// and u_has_ids, the id is the texel's of u_ids at the same texture coordinate (impostors: per-pixel object ids).
// FF_ITEM_BUFFER: a flat false colour of the object id, no texture sampling.

in vec3 v_world;
in vec3 v_normal;
in vec2 v_uv;
in vec4 v_uv_projected;

layout(location = 0) out vec4 o_color;
layout(location = 1) out uint o_id;

uniform uint u_object_id;

#ifdef FF_ITEM_BUFFER

void main() {
  uint h = u_object_id * 2654435761u;
  o_color = u_object_id == 0u ? vec4(0.0, 0.0, 0.0, 1.0)
                              : vec4(float((h >> 24) & 255u), float((h >> 16) & 255u), float((h >> 8) & 255u), 255.0) / 255.0;
  o_id = u_object_id;
}

#else

uniform vec4 u_base_color;
uniform int u_unlit;
uniform int u_projective_texture;  // 1: texture coordinate = v_uv_projected.xy / v_uv_projected.w
uniform vec3 u_light_dir;  // direction the light travels, unit length
uniform vec3 u_light_color;
uniform float u_ambient;
#ifdef FF_TEXTURED
layout(binding = 0) uniform sampler2D u_texture;
uniform int u_has_ids;  // 1: object ids per texel in u_ids (0 texels keep u_object_id)
layout(binding = 1) uniform usampler2D u_ids;
#endif

void main() {
  vec4 albedo = u_base_color;
#ifdef FF_TEXTURED
  const vec2 uv = u_projective_texture != 0 ? v_uv_projected.xy / v_uv_projected.w : v_uv;
  albedo *= texture(u_texture, uv);
  if (albedo.a < 0.5) discard;
#endif
  uint id = u_object_id;
#ifdef FF_TEXTURED
  if (u_has_ids != 0) {
    const ivec2 size = textureSize(u_ids, 0);
    const uint texel = texelFetch(u_ids, clamp(ivec2(floor(uv * vec2(size))), ivec2(0), size - 1), 0).r;
    if (texel != 0u) id = texel;
  }
#endif
  vec3 rgb = albedo.rgb;
  if (u_unlit == 0) {
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
