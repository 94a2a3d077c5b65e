// The textured mesh impostor (Sillion et al. 1997, section 3.2 and 4.2, step 6): 3D triangles reprojected from the
// capture's image plane, the captured colour as texture, and the creation camera. Built by buildDepthMesh()
// (depth_mesh.h) and by the regular-grid baseline buildGridMesh() (grid_mesh.h).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/image/image.h"
#include "farfield/impostor/depth_sampler.h"
#include "farfield/scene/mesh.h"

namespace farfield::impostor {

struct ImpostorBuildStats {
  size_t data_pixels = 0;
  size_t triangles = 0;
  size_t vertices = 0;
  // Depth mesh only (zero for the grid mesh):
  size_t contour_loops = 0;
  size_t contour_vertices = 0;         // = contour constraint segments
  size_t contour_dropped_loops = 0;
  size_t discrepancy_pixels = 0;       // pixels at or above the threshold
  size_t chains = 0;                   // with a polyline
  size_t short_chains = 0;
  size_t chain_segments = 0;           // discrepancy constraint segments
  size_t grid_points = 0;
  size_t steiner_vertices = 0;         // where constraints cross
  size_t refinement_vertices = 0;      // added to bound the texture warp
  // Both:
  size_t vertices_without_depth = 0;   // no data pixel near: their triangles are dropped
  size_t triangles_dropped = 0;
  // Timings (milliseconds): the bake's split of the work.
  double render_ms = 0.0;              // capture (filled by the callers that capture)
  double contour_ms = 0.0;
  double discrepancy_ms = 0.0;
  double triangulation_ms = 0.0;
  double reprojection_ms = 0.0;
  double total_ms = 0.0;               // everything after the capture
};

struct DepthMeshImpostor {
  // World-space triangles, counter-clockwise as seen from the creation camera; uvs are image coordinates divided
  // by the image size (uv (0, 0) = top-left, v down: the texture convention of gpu/texture.h), so from the
  // creation camera every point shows the texel it was captured in. Normals are left empty (the impostor is
  // drawn unlit).
  scene::Mesh mesh;
  // The captured colour, with alpha 255 on data pixels and 0 on background (sky, seen from below): the renderer
  // cuts out texels with alpha below 0.5, so the silhouette keeps the capture's resolution wherever a triangle
  // overhangs it. Null for an empty impostor.
  std::shared_ptr<const image::ColorImage> texture;
  Camera camera;                        // creation camera
  std::vector<uint32_t> triangle_ids;   // per triangle, majority object id of its pixels (empty without ids)
  // Per-texel object ids of the texture (0 away from the data), when the capture had ids: drawn as an id texture
  // (GpuImpostorOptions::id_texture), item buffers show the object of every impostor pixel.
  std::shared_ptr<const image::IdImage> ids;
  ImpostorBuildStats stats;

  bool empty() const { return mesh.indices.empty(); }
};

// Projective texture matrix of a creation camera: maps a world point (x, y, z, 1) to (u w, v w, 0, w) where (u, v)
// is its position in the camera's image divided by the image size (uv convention above). For
// gpu::GpuMaterial::texture_projection: every point of an impostor then shows the texel captured along its ray,
// exactly, where interpolating the mesh's uvs across a triangle with vertices at different depths shifts the
// texture (by about edge_length * |d1 - d2| / (2 (d1 + d2)) pixels in the creation view).
Mat4 textureProjection(const Camera& camera);

// The impostor texture: colour with alpha from the data mask.
std::shared_ptr<const image::ColorImage> impostorTexture(const image::ColorImage& color,
                                                         const image::Image<uint8_t>& mask);
// The capture's ids where the mask marks data, grown by two texels into the background, 0 elsewhere
// (DepthMeshImpostor::ids).
std::shared_ptr<const image::IdImage> impostorIds(const image::IdImage& ids, const image::Image<uint8_t>& mask);

// Reprojects 2D triangles (image coordinates, either orientation) to the impostor mesh: each vertex used by a
// triangle gets the sampler's window depth (DepthSampler's rule, searching at most max_search_px for data; < 0: no
// limit) and Camera::unproject; triangles with a vertex without depth are dropped and counted. With `ids`, each
// triangle's object id is the most frequent non-zero id among the pixels whose centre it covers (the pixel under
// its centroid when it covers none). Fills mesh, triangle_ids and the vertex/triangle counts of `out.stats`.
void assembleMesh(const std::vector<DVec2>& points, const std::vector<std::array<uint32_t, 3>>& triangles,
                  const DepthSampler& sampler, int max_search_px, const Camera& camera, const image::IdImage* ids,
                  DepthMeshImpostor& out);

// Calls fn(x, y) for each pixel of a width x height image whose centre lies in the closed triangle (either
// orientation; nothing for a degenerate one).
template <class Fn>
void forEachPixelCentreIn(const DVec2& a, const DVec2& b, const DVec2& c, int width, int height, Fn&& fn) {
  const double area = cross2(b - a, c - a);
  if (area == 0.0) return;
  const double s = area > 0.0 ? 1.0 : -1.0;
  const int x0 = std::max(0, int(std::floor(std::min({a.x, b.x, c.x}) - 0.5)));
  const int x1 = std::min(width - 1, int(std::ceil(std::max({a.x, b.x, c.x}) - 0.5)));
  const int y0 = std::max(0, int(std::floor(std::min({a.y, b.y, c.y}) - 0.5)));
  const int y1 = std::min(height - 1, int(std::ceil(std::max({a.y, b.y, c.y}) - 0.5)));
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      const DVec2 p(x + 0.5, y + 0.5);
      if (s * cross2(b - a, p - a) >= 0.0 && s * cross2(c - b, p - b) >= 0.0 && s * cross2(a - c, p - c) >= 0.0)
        fn(x, y);
    }
}

}  // namespace farfield::impostor
