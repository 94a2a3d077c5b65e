// Textured depth-mesh impostor (Sillion et al. 1997, section 4.2, "Impostor creation"): steps 3 to 6 on a captured
// colour and depth image, in the paper's order.
//
// Vertex depth: see depth_sampler.h. Contour vertices sit on pixel corners and take the nearest data pixel that
// touches them, never the background; discrepancy polylines run through pixel centres on each side of a step, so
// their vertices take the depth of their own side; grid points sit at pixel centres away from both.
//
// Why the contour is traced around the dilated data: Douglas-Peucker moves the boundary by up to its tolerance
// both ways, and every data pixel it cuts off would show the sky behind the impostor even from the creation
// point. Traced one pixel further out, the simplified contour keeps all data pixels inside; the texture's alpha
// (0 on background) cuts the overhang back to the captured silhouette, at the texture's resolution rather than
// the mesh's.
//
// Texture warp refinement (an addition to the paper, off by default): a renderer that interpolates the mesh's
// uvs across a 3D triangle, instead of projecting the texture from the creation camera (textureProjection()),
// shows a shifted texel wherever the triangle's vertices lie at different depths (the ground, a facade seen at a
// grazing angle). Splitting such triangles until the estimated shift is below max_texture_warp_px keeps the
// creation view faithful for those renderers. Triangles that span a depth discontinuity (the one-pixel strips
// between discrepancy chains) are left alone: they are narrow, and splitting them would only add vertices along
// the step.
#include "farfield/impostor/depth_mesh.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "farfield/core/error.h"
#include "farfield/core/timer.h"
#include "farfield/impostor/triangulation.h"

namespace farfield::impostor {
namespace {

// Chessboard distance (in pixels) from each pixel to the nearest pixel where `source` is set; pixels outside the
// image count as sources when `border_is_source`.
std::vector<int> chessboardDistance(const image::Image<uint8_t>& source, bool border_is_source) {
  const int w = source.width(), h = source.height();
  const int big = w + h + 2;
  std::vector<int> d(size_t(w) * size_t(h), big);
  auto at = [&](int x, int y) -> int& { return d[size_t(y) * size_t(w) + size_t(x)]; };
  auto get = [&](int x, int y) {
    if (x < 0 || y < 0 || x >= w || y >= h) return border_is_source ? -1 : big;
    return at(x, y);
  };
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (source.at(x, y)) {
        at(x, y) = 0;
        continue;
      }
      at(x, y) = std::min({at(x, y), get(x - 1, y) + 1, get(x - 1, y - 1) + 1, get(x, y - 1) + 1,
                           get(x + 1, y - 1) + 1});
    }
  for (int y = h - 1; y >= 0; --y)
    for (int x = w - 1; x >= 0; --x)
      at(x, y) = std::min({at(x, y), get(x + 1, y) + 1, get(x + 1, y + 1) + 1, get(x, y + 1) + 1,
                           get(x - 1, y + 1) + 1});
  return d;
}

// The mask grown by `passes` pixels (8-neighbour dilation).
image::Image<uint8_t> dilate(const image::Image<uint8_t>& mask, int passes) {
  const int w = mask.width(), h = mask.height();
  image::Image<uint8_t> grown = mask;
  for (int pass = 0; pass < passes; ++pass) {
    const image::Image<uint8_t> previous = grown;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        if (previous.at(x, y)) continue;
        bool touches = false;
        for (int dy = -1; dy <= 1 && !touches; ++dy)
          for (int dx = -1; dx <= 1 && !touches; ++dx) {
            const int nx = x + dx, ny = y + dy;
            touches = nx >= 0 && ny >= 0 && nx < w && ny < h && previous.at(nx, ny);
          }
        if (touches) grown.at(x, y) = 1;
      }
  }
  return grown;
}

}  // namespace

Camera creationCamera(const Vec3& eye, const Vec3& at, const DepthMeshOptions& options, float near_plane,
                      float far_plane) {
  Camera camera;
  camera.eye = eye;
  camera.at = at;
  camera.up = Vec3(0.0f, 0.0f, 1.0f);
  camera.fov_y = options.fov_y;
  camera.width = camera.height = options.resolution;
  camera.near_plane = near_plane;
  camera.far_plane = far_plane;
  camera.validate("impostor creation camera");
  return camera;
}

DepthMeshImpostor buildDepthMesh(const image::ColorImage& color, const image::DepthImage& depth,
                                 const Camera& camera, const DepthMeshOptions& options, const image::IdImage* ids) {
  Stopwatch total;
  camera.validate("impostor camera");
  if (color.width() != camera.width || color.height() != camera.height)
    throw Error("impostor capture", "colour image is " + std::to_string(color.width()) + "x" +
                                        std::to_string(color.height()) + " but the camera is " +
                                        std::to_string(camera.width) + "x" + std::to_string(camera.height));
  if (depth.width() != camera.width || depth.height() != camera.height)
    throw Error("impostor capture", "depth image is " + std::to_string(depth.width()) + "x" +
                                        std::to_string(depth.height()) + " but the camera is " +
                                        std::to_string(camera.width) + "x" + std::to_string(camera.height));
  if (ids && (ids->width() != camera.width || ids->height() != camera.height))
    throw Error("impostor capture", "id image size differs from the camera's");
  const int w = camera.width, h = camera.height;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float z = depth.at(x, y);
      if (!(z >= 0.0f && z <= 1.0f))
        throw Error("impostor capture", "depth image pixel (" + std::to_string(x) + ", " + std::to_string(y) +
                                            "): window depth " + std::to_string(z) + " is not in [0, 1]");
    }

  DepthMeshImpostor out;
  out.camera = camera;
  // Step 3: external contour(s).
  Stopwatch step;
  const image::Image<uint8_t> mask = dataMask(color, depth);
  for (uint8_t v : mask.pixels()) out.stats.data_pixels += v;
  if (out.stats.data_pixels == 0) {
    out.stats.total_ms = total.milliseconds();
    return out;
  }
  const Contours contours = extractContours(dilate(mask, options.contour_dilation_px), options.contour);
  out.stats.contour_loops = contours.loops.size();
  out.stats.contour_vertices = contours.vertexCount();
  out.stats.contour_dropped_loops = contours.dropped_loops;
  out.stats.contour_ms = step.milliseconds();

  // Step 2 (kept linearised) and step 4: depth discrepancy lines.
  step.restart();
  const image::DepthImage linear = linearizeDepth(depth, mask, camera);
  const DiscrepancyLines lines = extractDiscrepancyLines(linear, mask, options.discrepancy);
  out.stats.discrepancy_pixels = lines.pixels_above;
  out.stats.short_chains = lines.short_chains;
  out.stats.chain_segments = lines.segmentCount();
  out.stats.discrepancy_ms = step.milliseconds();

  // Step 5: grid points and the constrained Delaunay triangulation.
  step.restart();
  TriangulationInput input;
  for (const ContourLoop& loop : contours.loops) input.loops.push_back(loop.points);
  image::Image<uint8_t> chain_pixels(w, h, 0);
  for (const DiscrepancyChain& chain : lines.chains) {
    if (chain.polyline.size() < 2) continue;
    ++out.stats.chains;
    input.polylines.push_back(chain.polyline);
    for (const IVec2& p : chain.pixels) chain_pixels.at(p.x, p.y) = 1;
  }
  if (options.grid_spacing_px > 0.0) {
    image::Image<uint8_t> background(w, h, 0);
    for (size_t i = 0; i < mask.pixelCount(); ++i) background.pixels()[i] = mask.pixels()[i] ? 0 : 1;
    const std::vector<int> to_background = chessboardDistance(background, true);
    const std::vector<int> to_chain = chessboardDistance(chain_pixels, false);
    const int contour_margin = int(std::ceil(options.contour.tolerance_px)) + 2;
    const LoopClassifier inside(input.loops);
    const double s = options.grid_spacing_px;
    for (double gy = 0.5 * s; gy < h; gy += s)
      for (double gx = 0.5 * s; gx < w; gx += s) {
        const int x = int(gx), y = int(gy);
        const size_t i = size_t(y) * size_t(w) + size_t(x);
        if (to_background[i] < contour_margin || to_chain[i] < 2) continue;
        const DVec2 p(x + 0.5, y + 0.5);
        if (!inside.inside(p)) continue;  // in a hole dropped by the contour's minimum area, for instance
        input.points.push_back(p);
      }
    out.stats.grid_points = input.points.size();
  }
  const DepthSampler sampler(depth, mask, linear, options.discrepancy);
  // Whether the segment [a, b] crosses a depth step: the depth of the pixels along it, sampled every half pixel
  // (so consecutive samples are 8-neighbours, as in the discrepancy image), jumps between two of them.
  auto crossesStep = [&](const DVec2& a, const DVec2& b) {
    const int steps = std::max(1, int(std::ceil(2.0 * glm::length(b - a))));
    float previous = -1.0f;
    for (int k = 0; k <= steps; ++k) {
      const auto source = sampler.sourcePixel(a + (b - a) * (double(k) / steps));
      if (!source) continue;
      const float d = linear.at(source->x, source->y);
      if (previous > 0.0f && !depthContinuous(previous, d, options.discrepancy)) return true;
      previous = d;
    }
    return false;
  };
  Refinement refinement;
  if (options.max_texture_warp_px > 0.0 && options.max_refinement_points > 0) {
    refinement.max_points = options.max_refinement_points;
    refinement.split_point = [&](const DVec2& a, const DVec2& b, const DVec2& c) -> std::optional<DVec2> {
      const DVec2 p[3] = {a, b, c};
      double d[3];
      for (int k = 0; k < 3; ++k) {
        const auto s = sampler.sample(p[k], std::max(0, options.contour_dilation_px) + 2);
        if (!s) return std::nullopt;
        d[k] = camera.linearDepth(s->window_depth);
      }
      double worst = options.max_texture_warp_px;
      int worst_edge = -1;
      for (int k = 0; k < 3; ++k) {
        const int j = (k + 1) % 3;
        const double length = glm::length(p[j] - p[k]);
        const double warp = length * std::abs(d[k] - d[j]) / (2.0 * (d[k] + d[j]));
        if (warp > worst && length > 1.0) {
          worst = warp;
          worst_edge = k;
        }
      }
      if (worst_edge < 0) return std::nullopt;
      // A triangle across a depth step (between the two chains of a discontinuity) is left alone.
      for (int k = 0; k < 3; ++k)
        if (crossesStep(p[k], p[(k + 1) % 3])) return std::nullopt;
      return 0.5 * (p[worst_edge] + p[(worst_edge + 1) % 3]);
    };
  }
  const Triangulation triangulation = triangulate(input, refinement.split_point ? &refinement : nullptr);
  out.stats.steiner_vertices = triangulation.steiner_vertices;
  out.stats.refinement_vertices = triangulation.refinement_vertices;
  out.stats.triangulation_ms = step.milliseconds();

  // Step 6: reprojection of the inside triangles, texture = the captured image.
  step.restart();
  std::vector<std::array<uint32_t, 3>> kept;
  kept.reserve(triangulation.insideCount());
  for (size_t i = 0; i < triangulation.triangles.size(); ++i)
    if (triangulation.inside[i]) kept.push_back(triangulation.triangles[i]);
  // Vertices are on or next to data (contour corners at most the dilation away, chain pixel centres, grid points,
  // crossings and midpoints of those), so a short search suffices; a vertex beyond it is counted and dropped.
  assembleMesh(triangulation.vertices, kept, sampler, std::max(0, options.contour_dilation_px) + 2, camera, ids, out);
  if (!out.empty()) out.texture = impostorTexture(color, mask);
  if (!out.empty() && ids) out.ids = impostorIds(*ids, mask);
  out.stats.reprojection_ms = step.milliseconds();
  out.stats.total_ms = total.milliseconds();
  return out;
}

DepthMeshImpostor buildDepthMesh(const ImpostorCapture& capture, const DepthMeshOptions& options) {
  DepthMeshImpostor out = buildDepthMesh(capture.color, capture.depth, capture.camera, options,
                                         capture.ids.empty() ? nullptr : &capture.ids);
  out.stats.render_ms = capture.render_ms;
  return out;
}

}  // namespace farfield::impostor
