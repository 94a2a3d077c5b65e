// Regular-grid impostor mesh, the baseline without the contour and discrepancy constraints of Sillion et al. 1997
// (section 4.2): same capture, same vertex depth rule (depth_sampler.h), same texture.
#include "farfield/impostor/grid_mesh.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "farfield/core/error.h"
#include "farfield/core/timer.h"
#include "farfield/impostor/contour.h"

namespace farfield::impostor {

DepthMeshImpostor buildGridMesh(const image::ColorImage& color, const image::DepthImage& depth, const Camera& camera,
                                const GridMeshOptions& options, const image::IdImage* ids) {
  Stopwatch total;
  camera.validate("impostor camera");
  const int w = camera.width, h = camera.height;
  if (color.width() != w || color.height() != h || depth.width() != w || depth.height() != h)
    throw Error("impostor capture", "colour " + std::to_string(color.width()) + "x" +
                                        std::to_string(color.height()) + " and depth " +
                                        std::to_string(depth.width()) + "x" + std::to_string(depth.height()) +
                                        " images must match the camera's " + std::to_string(w) + "x" +
                                        std::to_string(h));
  if (ids && (ids->width() != w || ids->height() != h))
    throw Error("impostor capture", "id image size differs from the camera's");
  if (!(options.grid_spacing_px >= 1.0))
    throw Error("grid mesh", "grid spacing must be at least 1 pixel, got " + std::to_string(options.grid_spacing_px));
  for (float z : depth.pixels())
    if (!(z >= 0.0f && z <= 1.0f))
      throw Error("impostor capture", "window depth " + std::to_string(z) + " is not in [0, 1]");

  DepthMeshImpostor out;
  out.camera = camera;
  const image::Image<uint8_t> mask = dataMask(color, depth);
  for (uint8_t v : mask.pixels()) out.stats.data_pixels += v;
  if (out.stats.data_pixels == 0) {
    out.stats.total_ms = total.milliseconds();
    return out;
  }
  Stopwatch step;
  const image::DepthImage linear = linearizeDepth(depth, mask, camera);
  const DepthSampler sampler(depth, mask, linear, options.continuity);

  // Grid vertices at multiples of the spacing, plus the image edge.
  auto ticks = [&](int size) {
    std::vector<double> t;
    for (double v = 0.0; v < size; v += options.grid_spacing_px) t.push_back(std::round(v));
    if (t.back() != size) t.push_back(size);
    t.erase(std::unique(t.begin(), t.end()), t.end());
    return t;
  };
  const std::vector<double> xs = ticks(w), ys = ticks(h);
  std::vector<DVec2> points;
  for (double y : ys)
    for (double x : xs) points.push_back(DVec2(x, y));
  const uint32_t nx = uint32_t(xs.size());
  std::vector<std::array<uint32_t, 3>> triangles;
  auto coversData = [&](const std::array<uint32_t, 3>& t) {
    bool any = false;
    forEachPixelCentreIn(points[t[0]], points[t[1]], points[t[2]], w, h, [&](int x, int y) {
      any = any || mask.at(x, y) != 0;
    });
    return any;
  };
  for (uint32_t j = 0; j + 1 < ys.size(); ++j)
    for (uint32_t i = 0; i + 1 < nx; ++i) {
      const uint32_t a = j * nx + i, b = a + 1, c = a + nx, d = c + 1;
      for (const std::array<uint32_t, 3>& t : {std::array<uint32_t, 3>{a, b, d}, std::array<uint32_t, 3>{a, d, c}}) {
        if (coversData(t))
          triangles.push_back(t);
        else
          ++out.stats.triangles_dropped;
      }
    }
  out.stats.triangulation_ms = step.milliseconds();
  step.restart();
  assembleMesh(points, triangles, sampler, -1, camera, ids, out);
  out.texture = impostorTexture(color, mask);
  if (ids) out.ids = impostorIds(*ids, mask);
  out.stats.reprojection_ms = step.milliseconds();
  out.stats.total_ms = total.milliseconds();
  return out;
}

DepthMeshImpostor buildGridMesh(const ImpostorCapture& capture, const GridMeshOptions& options) {
  DepthMeshImpostor out = buildGridMesh(capture.color, capture.depth, capture.camera, options,
                                        capture.ids.empty() ? nullptr : &capture.ids);
  out.stats.render_ms = capture.render_ms;
  return out;
}

}  // namespace farfield::impostor
