#version 450 core
// Farfield multi-view impostor fragment: the atlas cell's albedo times the agent's tint and the tint of the texel's
// colour region in the agent's outfit (as crowd.frag.glsl tints the geometry), lit from the baked normal turned by
// the agent's heading; the depth moved from the quad along the view by the baked depth, so agents intersect the
// scene and each other per texel. Coverage and region come from the albedo's alpha (crowd.frag.glsl's FF_CAPTURE
// code): the four texels around the sample, a texel covered when its alpha is at least 8/255; the fragment is kept
// where the bilinear weight of covered texels reaches 0.5 (the silhouette of a bilinear 0/1 mask), its region is
// that of the covered texel of largest weight, and its colour, normal and depth the bilinear ones of the covered texels alone.
// FF_DEPTH_ONLY (shadow casters): coverage and depth alone. FF_BLEND_VIEWS: the four views the vertex shader chose,
// each sampled as above and blended by its weight (coverage, colour, normal and depth; the region of the view and
// texel of largest weight), as octahedral impostors blend their nearest views.

in vec2 v_cell_uv;
in vec3 v_world;
flat in vec3 v_to_eye;
flat in vec4 v_tint;
flat in uvec4 v_data;
flat in float v_heading;

layout(binding = 0) uniform sampler2DArray u_albedo;
layout(binding = 1) uniform sampler2DArray u_normal_depth;
uniform ivec2 u_grid;  // azimuths, elevations
uniform float u_radius;
uniform mat4 u_view_proj;
#ifndef FF_DEPTH_ONLY
layout(location = 0) out vec4 o_color;
layout(location = 1) out uint o_id;
uniform vec3 u_light_dir;
uniform vec3 u_light_color;
uniform float u_ambient;
layout(std430, binding = 2) readonly buffer Tints { vec4 tints[]; };
uniform uint u_outfits;
#endif

#ifdef FF_BLEND_VIEWS
flat in uvec4 v_views;
flat in vec4 v_weights;
#endif

// One view's sample: bilinear coverage of the covered texels, their colour (premultiplied by the coverage), normal
// and depth (likewise), and the region and weight of the covered texel of largest bilinear weight.
struct Sample {
  float coverage;
  vec3 rgb;
  vec4 nd;
  uint region;
  float best;
};

Sample sampleView(int view) {
  const vec2 cell = vec2(float(view % u_grid.x), float(view / u_grid.x));
  const vec3 uvw = vec3((cell + v_cell_uv) / vec2(u_grid), float(v_data.x));
  // textureGather order: (u0, v1), (u1, v1), (u1, v0), (u0, v0) around the sample.
  const vec2 f = fract(uvw.xy * vec2(textureSize(u_albedo, 0).xy) - 0.5);
  const vec4 w = vec4((1.0 - f.x) * f.y, f.x * f.y, f.x * (1.0 - f.y), (1.0 - f.x) * (1.0 - f.y));
  const uvec4 alpha = uvec4(round(textureGather(u_albedo, uvw, 3) * 255.0));
  const vec4 covered = vec4(greaterThanEqual(alpha, uvec4(8u)));
  Sample r;
  r.coverage = dot(w, covered);
  r.rgb = texture(u_albedo, uvw).rgb;
  // Empty texels hold 0.5 (the bake's clear).
  r.nd = texture(u_normal_depth, uvw) - 0.5 * (1.0 - r.coverage);
  const vec4 wc = w * covered;
  int k = 0;
  for (int i = 1; i < 4; ++i)
    if (wc[i] > wc[k]) k = i;
  r.region = alpha[k] >= 8u ? (alpha[k] + 1u) / 16u - 1u : 0u;
  r.best = wc[k];
  return r;
}

void main() {
#ifdef FF_BLEND_VIEWS
  float coverage = 0.0, best = -1.0;
  vec3 rgb_sum = vec3(0.0);
  vec4 nd_sum = vec4(0.0);
  uint region = 0u;
  for (int i = 0; i < 4; ++i) {
    if (v_weights[i] <= 0.0) continue;
    const Sample one = sampleView(int(v_views[i]));
    coverage += v_weights[i] * one.coverage;
    rgb_sum += v_weights[i] * one.rgb;
    nd_sum += v_weights[i] * one.nd;
    if (v_weights[i] * one.best > best) {
      best = v_weights[i] * one.best;
      region = one.region;
    }
  }
#else
  const Sample one = sampleView(int(v_data.y));
  const float coverage = one.coverage;
  const vec3 rgb_sum = one.rgb;
  const vec4 nd_sum = one.nd;
  const uint region = one.region;
#endif
  if (coverage < 0.5) discard;
  // The covered texels' own colour, normal and depth.
  const vec4 nd = nd_sum / coverage;
  const vec3 world = v_world + v_to_eye * ((nd.w * 2.0 - 1.0) * u_radius);
  const vec4 clip = u_view_proj * vec4(world, 1.0);
  gl_FragDepth = clip.z / clip.w;
#ifndef FF_DEPTH_ONLY
  const vec3 rgb = rgb_sum / coverage;
  const vec3 albedo = rgb * v_tint.rgb * tints[(v_data.w % u_outfits) * 16u + region].rgb;
  const vec3 nl = nd.xyz * 2.0 - 1.0;
  const float c = cos(v_heading), s = sin(v_heading);
  vec3 n = vec3(c * nl.x - s * nl.y, s * nl.x + c * nl.y, nl.z);
  n = dot(n, n) > 1e-8 ? normalize(n) : v_to_eye;
  o_color = vec4(albedo * (vec3(u_ambient) + u_light_color * max(dot(n, -u_light_dir), 0.0)), 1.0);
  o_id = v_data.z;
#endif
}
