#version 450 core
// Farfield CDLOD terrain vertex shader (gpu/cdlod_renderer.h; the arithmetic of terrain/cdlod.cpp's
// CdlodTerrain::vertex, which the tests compare): patch vertex (i, j) from gl_VertexID, its node from the instance.
// With FF_PAGED (a terrain paged in tiles): a node whose instance names a page layer (w >= 0) reads its tile's page,
// (S + 1)^2 grid points from the tile's first; the others read the overview, every u_overview_step-th grid point
// (their vertices lie on it).
// With FF_CDLOD_SPRITE (LOD-sprite's frame on the GPU, terrain/lod_sprite.h): each vertex is also projected into the
// sprite's keyframe and tested against the keyframe's depth as terrain/keyframe_visibility.h's vertexVisible does
// (Chen et al. 1999, equation 3); v_hidden is 0 for a visible vertex and large otherwise, so that it interpolates to
// 0 only over a triangle whose three vertices are visible (terrain.frag.glsl then takes the sprite there). Paged, the
// vertex's normal comes from its node's source (page or overview).

layout(std430, binding = 0) readonly buffer Nodes { ivec4 nodes[]; };  // x0, y0, level, page layer (FF_PAGED)
layout(std430, binding = 1) readonly buffer Ranges { vec2 ranges[]; };  // per node: morph start and end
layout(binding = 1) uniform sampler2D u_heights;                        // R32F, a texel per grid point
#ifdef FF_PAGED
layout(binding = 2) uniform sampler2DArray u_pages;  // R32F pages, (S + 1)^2 texels each
uniform int u_page_cells;                             // S
uniform int u_overview_step;                          // u_heights holds every u_overview_step-th grid point
flat out int v_layer;
#endif

uniform mat4 u_view_proj;
uniform vec3 u_eye;
uniform vec2 u_cell;      // metres per grid step
uniform ivec2 u_last;     // the last grid point: (width - 1, height - 1)
uniform int u_patch;      // quads per patch side
uniform int u_top;                // the top level (never morphs)
uniform int u_level_offset[25];   // per level: index of node (0, 0) in `ranges`
uniform ivec2 u_level_count[25];  // per level: nodes along x and y
uniform vec2 u_uv_scale;
uniform vec2 u_uv_offset;

out vec2 v_uv;
out vec2 v_world_xy;  // for the fragment shader's hole (terrain.frag.glsl with FF_HOLE)
#ifdef FF_CDLOD_SPRITE
uniform mat4 u_sprite_view_proj;
layout(binding = 4) uniform sampler2D u_sprite_depth;  // the keyframe's window depth (reversed Z), row 0 at the bottom
uniform vec4 u_sprite_eye_beta;    // the keyframe's eye, and its view angle of one pixel (fovX / width)
uniform vec2 u_sprite_near_far;    // the keyframe camera's near and far planes
uniform vec3 u_sprite_thickness;   // VisibilityOptions: thickness_m, thickness_rel, footprint_pixels
out vec4 v_sprite_clip;
out float v_hidden;

#ifndef FF_PAGED
// The unit normal at grid point c from central differences, one-sided at the border (Heightfield::normal).
vec3 gridNormal(ivec2 c) {
  ivec2 lo = max(c - 1, ivec2(0)), hi = min(c + 1, u_last);
  float dzdx = hi.x > lo.x ? (texelFetch(u_heights, ivec2(hi.x, c.y), 0).r -
                              texelFetch(u_heights, ivec2(lo.x, c.y), 0).r) / (float(hi.x - lo.x) * u_cell.x) : 0.0;
  float dzdy = hi.y > lo.y ? (texelFetch(u_heights, ivec2(c.x, hi.y), 0).r -
                              texelFetch(u_heights, ivec2(c.x, lo.y), 0).r) / (float(hi.y - lo.y) * u_cell.y) : 0.0;
  return normalize(vec3(-dzdx, -dzdy, 1.0));
}
#endif

// Equation 3 (keyframe_visibility.cpp's vertexVisible): inside the keyframe, on its surface within the thickness.
bool spriteVisible(vec3 p, vec3 n, vec4 clip) {
  if (!(clip.w > 0.0)) return false;
  vec3 ndc = clip.xyz / clip.w;
  ivec2 size = textureSize(u_sprite_depth, 0);
  vec2 s = vec2((ndc.x * 0.5 + 0.5) * float(size.x), (0.5 - ndc.y * 0.5) * float(size.y));  // row 0 at the top
  if (!(s.x >= 0.0 && s.y >= 0.0 && s.x < float(size.x) && s.y < float(size.y))) return false;
  if (!(ndc.z >= 0.0 && ndc.z <= 1.0)) return false;
  float key_depth = texelFetch(u_sprite_depth, ivec2(int(s.x), size.y - 1 - int(s.y)), 0).r;
  if (!(key_depth > 0.0)) return false;  // background
  float zn = u_sprite_near_far.x, zf = u_sprite_near_far.y;
  float z_buffer = zn * zf / (key_depth * (zf - zn) + zn);
  float footprint = 0.0;
  if (u_sprite_thickness.z > 0.0) {
    float sin_a = abs(dot(n, normalize(u_sprite_eye_beta.xyz - p)));
    float cot_a = min(sqrt(max(1.0 - sin_a * sin_a, 0.0)) / max(sin_a, 1e-6), 20.0);
    footprint = u_sprite_thickness.z * u_sprite_eye_beta.w * cot_a;
  }
  return abs(clip.w - z_buffer) < u_sprite_thickness.x + (u_sprite_thickness.y + footprint) * clip.w;
}
#endif

float bilinear(vec2 g, ivec2 last, int layer) {
  g = clamp(g, vec2(0.0), vec2(last));
  ivec2 p0 = min(ivec2(floor(g)), last);
  ivec2 p1 = min(p0 + 1, last);
  vec2 f = g - vec2(p0);
#ifdef FF_PAGED
  if (layer >= 0) {
    float a = texelFetch(u_pages, ivec3(p0, layer), 0).r * (1.0 - f.x) +
              texelFetch(u_pages, ivec3(p1.x, p0.y, layer), 0).r * f.x;
    float b = texelFetch(u_pages, ivec3(p0.x, p1.y, layer), 0).r * (1.0 - f.x) +
              texelFetch(u_pages, ivec3(p1, layer), 0).r * f.x;
    return a * (1.0 - f.y) + b * f.y;
  }
#endif
  float a = texelFetch(u_heights, p0, 0).r * (1.0 - f.x) + texelFetch(u_heights, ivec2(p1.x, p0.y), 0).r * f.x;
  float b = texelFetch(u_heights, ivec2(p0.x, p1.y), 0).r * (1.0 - f.x) + texelFetch(u_heights, p1, 0).r * f.x;
  return a * (1.0 - f.y) + b * f.y;
}

#ifdef FF_PAGED
// Grid coordinates into the node's source: its page (from the tile's first point) or the overview.
vec2 sourceCoord(vec2 g, ivec2 tile_origin, int layer) {
  return layer >= 0 ? g - vec2(tile_origin) : g / float(u_overview_step);
}
ivec2 sourceLast(int layer) {
  return layer >= 0 ? ivec2(u_page_cells) : textureSize(u_heights, 0) - 1;
}
#ifdef FF_CDLOD_SPRITE
float sourceHeight(ivec2 p, int layer) {
  return layer >= 0 ? texelFetch(u_pages, ivec3(p, layer), 0).r : texelFetch(u_heights, p, 0).r;
}
// The unit normal at the source point nearest grid coordinates gm, from central differences over the node's source:
// its page (the grid's own points; one-sided at the page's edge) or the overview (every u_overview_step-th point).
vec3 sourceNormal(vec2 gm, ivec2 tile_origin, int layer, ivec2 last) {
  ivec2 c = clamp(ivec2(floor(sourceCoord(gm, tile_origin, layer) + 0.5)), ivec2(0), last);
  ivec2 lo = max(c - 1, ivec2(0)), hi = min(c + 1, last);
  vec2 spacing = u_cell * (layer >= 0 ? 1.0 : float(u_overview_step));
  float dzdx = hi.x > lo.x ? (sourceHeight(ivec2(hi.x, c.y), layer) - sourceHeight(ivec2(lo.x, c.y), layer)) /
                                 (float(hi.x - lo.x) * spacing.x) : 0.0;
  float dzdy = hi.y > lo.y ? (sourceHeight(ivec2(c.x, hi.y), layer) - sourceHeight(ivec2(c.x, lo.y), layer)) /
                                 (float(hi.y - lo.y) * spacing.y) : 0.0;
  return normalize(vec3(-dzdx, -dzdy, 1.0));
}
#endif
#endif

void main() {
  ivec4 node = nodes[gl_InstanceID];
  int i = gl_VertexID % (u_patch + 1), j = gl_VertexID / (u_patch + 1);
  int s = 1 << node.z;
  ivec2 g = node.xy + ivec2(i, j) * s;
  ivec2 c = min(g, u_last);
#ifdef FF_PAGED
  int layer = node.w;
  ivec2 tile_origin = (node.xy / u_page_cells) * u_page_cells;
  ivec2 last = sourceLast(layer);
  float h0 = bilinear(sourceCoord(vec2(c), tile_origin, layer), last, layer);
  v_layer = layer;
#else
  int layer = -1;
  ivec2 last = u_last;
  float h0 = texelFetch(u_heights, c, 0).r;
#endif
  ivec2 odd = ivec2(i & 1, j & 1);
  float k = 0.0;
  if (node.z < u_top && (odd.x | odd.y) != 0) {  // even vertices never move
    // The range: the largest over the next level's nodes the vertex lies in (two or four on their borders).
    float d = length(u_eye - vec3(vec2(c) * u_cell, h0));
    int up = node.z + 1, cells = u_patch << up;
    ivec2 count = u_level_count[up];
    ivec2 hi = min(c / cells, count - 1);
    ivec2 lo = min(ivec2(c.x % cells == 0 && c.x > 0 ? c.x / cells - 1 : hi.x,
                         c.y % cells == 0 && c.y > 0 ? c.y / cells - 1 : hi.y), count - 1);
    int base = u_level_offset[up];
    vec2 m = max(max(ranges[base + lo.x + lo.y * count.x], ranges[base + hi.x + lo.y * count.x]),
                 max(ranges[base + lo.x + hi.y * count.x], ranges[base + hi.x + hi.y * count.x]));
    if (m.y > m.x) k = clamp((d - m.x) / (m.y - m.x), 0.0, 1.0);
  }
  vec2 gm = vec2(g) - vec2(odd) * (float(s) * k);
  gm = min(gm, vec2(u_last));
  // Unmoved (k = 0, or an even vertex): the grid point's height, which the bilinear interpolation gives exactly.
#ifdef FF_PAGED
  vec2 source = sourceCoord(gm, tile_origin, layer);
  vec3 world = vec3(gm * u_cell, k > 0.0 ? bilinear(source, last, layer) : h0);
  v_uv = (source + 0.5) / vec2(last + 1);  // texel centres on the source's points
#else
  vec3 world = vec3(gm * u_cell, k > 0.0 ? bilinear(gm, last, layer) : h0);
  v_uv = world.xy * u_uv_scale + u_uv_offset;
#endif
  v_world_xy = world.xy;
#ifdef FF_CDLOD_SPRITE
  v_sprite_clip = u_sprite_view_proj * vec4(world, 1.0);
  // The normal of the grid point nearest the (possibly morphed) vertex.
#ifdef FF_PAGED
  vec3 normal = sourceNormal(gm, tile_origin, layer, last);
#else
  vec3 normal = gridNormal(min(ivec2(floor(gm + 0.5)), u_last));
#endif
  v_hidden = spriteVisible(world, normal, v_sprite_clip) ? 0.0 : 1e6;
#endif
  gl_Position = u_view_proj * vec4(world, 1.0);
}
