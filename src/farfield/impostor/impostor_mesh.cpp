// Reprojection of the triangulated image plane to the 3D impostor mesh (Sillion et al. 1997, section 4.2, step 6:
// "All vertices of the triangulation are then reprojected in 3D using the information of the depth image ...
// Texture coordinates for each triangle vertex are simply the image coordinates").
#include "farfield/impostor/impostor_mesh.h"

#include <unordered_map>

namespace farfield::impostor {

Mat4 textureProjection(const Camera& camera) {
  // Clip (x, y, z, w) -> (0.5 x + 0.5 w, -0.5 y + 0.5 w, 0, w): after the divide, u = (ndc_x + 1) / 2 and
  // v = (1 - ndc_y) / 2 (row 0 at the top, as Camera::project).
  Mat4 s(0.0f);
  s[0][0] = 0.5f;
  s[1][1] = -0.5f;
  s[3][0] = 0.5f;
  s[3][1] = 0.5f;
  s[3][3] = 1.0f;
  return s * camera.viewProjection();
}

std::shared_ptr<const image::ColorImage> impostorTexture(const image::ColorImage& color,
                                                         const image::Image<uint8_t>& mask) {
  auto texture = std::make_shared<image::ColorImage>(color);
  for (size_t i = 0; i < texture->pixelCount(); ++i) texture->pixels()[i].a = mask.pixels()[i] ? 255 : 0;
  return texture;
}

std::shared_ptr<const image::IdImage> impostorIds(const image::IdImage& ids, const image::Image<uint8_t>& mask) {
  auto out = std::make_shared<image::IdImage>(ids);
  for (size_t i = 0; i < out->pixelCount(); ++i)
    if (!mask.pixels()[i]) out->pixels()[i] = 0;
  // Grown by two texels into the background: the colour texture's alpha is filtered bilinearly, so a pixel at the
  // silhouette can pass the alpha test where the nearest id texel is background; it gets its neighbour's id.
  const int w = out->width(), h = out->height();
  for (int pass = 0; pass < 2; ++pass) {
    const image::IdImage before = *out;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        if (before.at(x, y) != 0) continue;
        for (int dy = -1; dy <= 1 && out->at(x, y) == 0; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int nx = x + dx, ny = y + dy;
            if (nx < 0 || ny < 0 || nx >= w || ny >= h || before.at(nx, ny) == 0) continue;
            out->at(x, y) = before.at(nx, ny);
            break;
          }
      }
  }
  return out;
}

void assembleMesh(const std::vector<DVec2>& points, const std::vector<std::array<uint32_t, 3>>& triangles,
                  const DepthSampler& sampler, int max_search_px, const Camera& camera, const image::IdImage* ids,
                  DepthMeshImpostor& out) {
  constexpr uint32_t kUnset = 0xffffffffu, kNoDepth = 0xfffffffeu;
  std::vector<uint32_t> remap(points.size(), kUnset);
  scene::Mesh& mesh = out.mesh;
  const double inv_w = 1.0 / double(camera.width), inv_h = 1.0 / double(camera.height);
  auto vertex = [&](uint32_t i) {
    if (remap[i] != kUnset) return remap[i];
    const auto s = sampler.sample(points[i], max_search_px);
    if (!s) {
      ++out.stats.vertices_without_depth;
      return remap[i] = kNoDepth;
    }
    remap[i] = uint32_t(mesh.positions.size());
    mesh.positions.push_back(camera.unproject(float(points[i].x), float(points[i].y), s->window_depth));
    mesh.uvs.push_back(Vec2(float(points[i].x * inv_w), float(points[i].y * inv_h)));
    return remap[i];
  };
  std::unordered_map<uint32_t, uint32_t> votes;
  for (const auto& t : triangles) {
    const uint32_t a = vertex(t[0]), b = vertex(t[1]), c = vertex(t[2]);
    if (a == kNoDepth || b == kNoDepth || c == kNoDepth) {
      ++out.stats.triangles_dropped;
      continue;
    }
    // Counter-clockwise in window coordinates (y up) = clockwise in image coordinates (y down): GL's front face
    // for the creation camera.
    const DVec2 pa = points[t[0]], pb = points[t[1]], pc = points[t[2]];
    if (cross2(pb - pa, pc - pa) > 0.0)
      mesh.indices.insert(mesh.indices.end(), {a, c, b});
    else
      mesh.indices.insert(mesh.indices.end(), {a, b, c});
    if (ids) {
      votes.clear();
      forEachPixelCentreIn(pa, pb, pc, ids->width(), ids->height(), [&](int x, int y) {
        const uint32_t id = ids->at(x, y);
        if (id) ++votes[id];
      });
      uint32_t best = 0, best_count = 0;
      for (const auto& [id, count] : votes)
        if (count > best_count || (count == best_count && id < best)) {
          best = id;
          best_count = count;
        }
      if (best_count == 0) {
        const DVec2 centroid = (pa + pb + pc) / 3.0;
        const auto source = sampler.sourcePixel(centroid, -1);
        if (source) best = ids->at(source->x, source->y);
      }
      out.triangle_ids.push_back(best);
    }
  }
  mesh.computeBounds();
  out.stats.triangles = mesh.triangleCount();
  out.stats.vertices = mesh.vertexCount();
}

}  // namespace farfield::impostor
