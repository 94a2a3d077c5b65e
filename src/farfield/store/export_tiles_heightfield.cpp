// Heightfield mesh of a top-down capture and its simplification (see the header).
#include "farfield/store/export_tiles_heightfield.h"

#include <meshoptimizer.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/impostor/contour.h"

namespace farfield::store {

scene::Mesh heightfieldMesh(const impostor::ImpostorCapture& capture) {
  const Camera& cam = capture.camera;
  const int w = cam.width, h = cam.height;
  if (capture.depth.width() != w || capture.depth.height() != h || capture.color.width() != w ||
      capture.color.height() != h)
    throw Error("heightfield mesh", "capture images of " + std::to_string(capture.depth.width()) + "x" +
                                        std::to_string(capture.depth.height()) + " do not match the camera's " +
                                        std::to_string(w) + "x" + std::to_string(h));
  // Camera::unproject with the inverse view computed once.
  const Mat4 inv_view = glm::inverse(cam.view());
  const float t = std::tan(cam.fov_y * 0.5f);
  scene::Mesh mesh;
  std::vector<uint32_t> vertex(size_t(w) * size_t(h), UINT32_MAX);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float depth = capture.depth.at(x, y);
      if (!impostor::isImpostorData(capture.color.at(x, y), depth)) continue;
      const float d = cam.linearDepth(depth);
      const float px = float(x) + 0.5f, py = float(y) + 0.5f;
      const Vec4 view(((px / float(w)) * 2.0f - 1.0f) * t * cam.aspect() * d, (1.0f - (py / float(h)) * 2.0f) * t * d,
                      -d, 1.0f);
      vertex[size_t(y) * size_t(w) + size_t(x)] = uint32_t(mesh.positions.size());
      mesh.positions.push_back(Vec3(inv_view * view));
      mesh.uvs.emplace_back(px / float(w), py / float(h));
    }
  auto at = [&](int x, int y) { return vertex[size_t(y) * size_t(w) + size_t(x)]; };
  auto tri = [&](uint32_t a, uint32_t b, uint32_t c) {
    if (a == UINT32_MAX || b == UINT32_MAX || c == UINT32_MAX) return;
    // Counter-clockwise seen from above (image y grows southwards: swap to keep +z normals).
    mesh.indices.insert(mesh.indices.end(), {a, c, b});
  };
  for (int y = 0; y + 1 < h; ++y)
    for (int x = 0; x + 1 < w; ++x) {
      const uint32_t a = at(x, y), b = at(x + 1, y), c = at(x, y + 1), d = at(x + 1, y + 1);
      const int present = (a != UINT32_MAX) + (b != UINT32_MAX) + (c != UINT32_MAX) + (d != UINT32_MAX);
      if (present < 3) continue;
      auto z = [&](uint32_t v) { return mesh.positions[v].z; };
      // Diagonal a-d or b-c: the one whose ends are closer in height (both must exist).
      const bool ad = a != UINT32_MAX && d != UINT32_MAX &&
                      (b == UINT32_MAX || c == UINT32_MAX || std::abs(z(a) - z(d)) <= std::abs(z(b) - z(c)));
      if (ad) {
        tri(a, b, d);
        tri(a, d, c);
      } else {
        tri(a, b, c);
        tri(b, d, c);
      }
    }
  mesh.computeBounds();
  return mesh;
}

void simplifyMesh(scene::Mesh& mesh, double error_m) {
  const size_t n = mesh.positions.size();
  if (n == 0 || mesh.indices.empty()) return;
  const float scale = meshopt_simplifyScale(&mesh.positions[0].x, n, sizeof(Vec3));
  std::vector<uint32_t> indices(mesh.indices.size());
  float result = 0.0f;
  indices.resize(meshopt_simplify(indices.data(), mesh.indices.data(), mesh.indices.size(), &mesh.positions[0].x, n,
                                  sizeof(Vec3), 0, scale > 0.0f ? float(error_m) / scale : 0.0f, 0, &result));
  std::vector<uint32_t> remap(n, UINT32_MAX);
  scene::Mesh out;
  for (uint32_t& i : indices) {
    if (remap[i] == UINT32_MAX) {
      remap[i] = uint32_t(out.positions.size());
      out.positions.push_back(mesh.positions[i]);
      if (mesh.uvs.size() == n) out.uvs.push_back(mesh.uvs[i]);
    }
    i = remap[i];
  }
  out.indices = std::move(indices);
  out.computeBounds();
  mesh = std::move(out);
}

}  // namespace farfield::store
