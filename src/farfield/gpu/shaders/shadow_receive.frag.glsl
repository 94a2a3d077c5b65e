#version 450 core
// Farfield shadow receivers (Steed's lecture part 3, "Impostors & shadowmaps"; gpu/shadow_map.h): for each pixel of
// the frame that is neither sky nor an agent, within u_max_distance along the view, the world point from the depth buffer, its light-space depth compared
// with the agents' shadow map over the 4x4 texels around it (four gathers of compared texels: lit share s), and the colour multiplied (blending: dst * src)
// by mix(ambient / (ambient + light * max(n . -l, 0)), 1, s): the lighting of mesh.frag.glsl without its direct
// term. The normal n comes from the depth buffer: on each axis the nearer of the two neighbours, facing the eye.

layout(location = 0) out vec4 o_factor;

layout(binding = 0) uniform sampler2D u_depth;   // reversed Z, 0 = sky
layout(binding = 1) uniform usampler2D u_ids;
layout(binding = 2) uniform sampler2DShadow u_shadow;
uniform mat4 u_inv_view_proj;
uniform mat4 u_light_view_proj;
uniform float u_bias;  // light depth units
uniform uint u_agent_mask;
uniform vec3 u_light_dir;
uniform vec3 u_light_color;
uniform float u_ambient;
uniform vec3 u_eye;
uniform vec3 u_forward;       // unit view direction
uniform float u_max_distance;  // receivers up to this far along the view (metres)

vec3 worldAt(ivec2 p, float depth) {
  const vec2 ndc = (vec2(p) + 0.5) / vec2(textureSize(u_depth, 0)) * 2.0 - 1.0;
  const vec4 w = u_inv_view_proj * vec4(ndc, depth, 1.0);
  return w.xyz / w.w;
}

// The neighbour on the side (of -step, +step) whose depth is nearer the pixel's: a central difference that does not
// cross a depth edge.
vec3 tangent(ivec2 p, ivec2 step, vec3 centre, float depth) {
  const ivec2 size = textureSize(u_depth, 0);
  const ivec2 a = clamp(p - step, ivec2(0), size - 1), b = clamp(p + step, ivec2(0), size - 1);
  const float da = texelFetch(u_depth, a, 0).r, db = texelFetch(u_depth, b, 0).r;
  if (abs(da - depth) < abs(db - depth) && da > 0.0) return centre - worldAt(a, da);
  if (db > 0.0) return worldAt(b, db) - centre;
  return da > 0.0 ? centre - worldAt(a, da) : vec3(0.0);
}

void main() {
  const ivec2 p = ivec2(gl_FragCoord.xy);
  const float depth = texelFetch(u_depth, p, 0).r;
  if (depth <= 0.0 || (texelFetch(u_ids, p, 0).r & u_agent_mask) != 0u) discard;
  const vec3 world = worldAt(p, depth);
  if (dot(world - u_eye, u_forward) > u_max_distance) discard;
  const vec4 lc = u_light_view_proj * vec4(world, 1.0);
  const vec3 l = lc.xyz / lc.w;
  if (any(greaterThan(abs(l.xy), vec2(1.0)))) discard;  // outside the map: no caster
  // Nearer the light than every caster: lit; beyond the map's far plane: compared at 1 (behind every caster).
  if (l.z < 0.0) discard;
  const vec2 uv = l.xy * 0.5 + 0.5;
  const float ref = min(l.z, 1.0) - u_bias;
  const vec2 texel = 1.0 / vec2(textureSize(u_shadow, 0));
  const vec4 ones = vec4(1.0);
  const float lit = (dot(textureGather(u_shadow, uv + vec2(-1.0, -1.0) * texel, ref), ones) +
                     dot(textureGather(u_shadow, uv + vec2(1.0, -1.0) * texel, ref), ones) +
                     dot(textureGather(u_shadow, uv + vec2(-1.0, 1.0) * texel, ref), ones) +
                     dot(textureGather(u_shadow, uv + vec2(1.0, 1.0) * texel, ref), ones)) / 16.0;
  if (lit >= 1.0) discard;
  vec3 n = cross(tangent(p, ivec2(1, 0), world, depth), tangent(p, ivec2(0, 1), world, depth));
  if (dot(n, n) < 1e-20) discard;
  n = normalize(n);
  if (dot(n, u_eye - world) < 0.0) n = -n;
  const vec3 direct = u_light_color * max(dot(n, -u_light_dir), 0.0);
  const vec3 shadowed = vec3(u_ambient) / max(vec3(u_ambient) + direct, vec3(1e-6));
  o_factor = vec4(mix(shadowed, vec3(1.0), lit), 1.0);
}
