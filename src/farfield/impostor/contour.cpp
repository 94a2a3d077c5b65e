// External contour extraction (Sillion et al. 1997, section 4.2, step 3): thresholding the capture into data and
// background ("seen from below" pixels count as background), boundary tracing along pixel edges, Douglas-Peucker.
#include "farfield/impostor/contour.h"

#include <cmath>
#include <string>

#include "farfield/core/check.h"
#include "farfield/core/error.h"
#include "farfield/core/douglas_peucker.h"

namespace farfield::impostor {
namespace {

// Directions of pixel edges, clockwise on screen (y down): a right turn is +1.
enum Dir : int { kEast = 0, kSouth = 1, kWest = 2, kNorth = 3 };
constexpr int kDx[4] = {1, 0, -1, 0};
constexpr int kDy[4] = {0, 1, 0, -1};

std::vector<DVec2> removeCollinear(const std::vector<DVec2>& loop) {
  const size_t n = loop.size();
  std::vector<DVec2> out;
  for (size_t i = 0; i < n; ++i) {
    const DVec2& prev = loop[(i + n - 1) % n];
    const DVec2& next = loop[(i + 1) % n];
    if (cross2(loop[i] - prev, next - loop[i]) != 0.0) out.push_back(loop[i]);
  }
  return out;
}

}  // namespace

image::Image<uint8_t> dataMask(const image::ColorImage& color, const image::DepthImage& depth) {
  if (color.width() != depth.width() || color.height() != depth.height())
    throw Error("impostor capture", "colour image is " + std::to_string(color.width()) + "x" +
                                        std::to_string(color.height()) + " but depth image is " +
                                        std::to_string(depth.width()) + "x" + std::to_string(depth.height()));
  image::Image<uint8_t> mask(color.width(), color.height(), 0);
  for (size_t i = 0; i < mask.pixelCount(); ++i)
    mask.pixels()[i] = isImpostorData(color.pixels()[i], depth.pixels()[i]) ? 1 : 0;
  return mask;
}

double signedArea(const std::vector<DVec2>& polygon) {
  double a = 0.0;
  const size_t n = polygon.size();
  for (size_t i = 0; i < n; ++i) a += cross2(polygon[i], polygon[(i + 1) % n]);
  return 0.5 * a;
}

size_t Contours::vertexCount() const {
  size_t n = 0;
  for (const ContourLoop& loop : loops) n += loop.points.size();
  return n;
}

std::vector<std::vector<DVec2>> traceBoundaries(const image::Image<uint8_t>& mask) {
  const int w = mask.width(), h = mask.height();
  const int cw = w + 1;  // corners per row
  auto data = [&](int x, int y) { return x >= 0 && y >= 0 && x < w && y < h && mask.at(x, y) != 0; };
  auto corner = [&](int x, int y) { return size_t(y) * size_t(cw) + size_t(x); };

  // Directed boundary edges with the data pixel on their right on screen (so outer loops run clockwise on screen,
  // which is a positive shoelace area with y down), stored as a direction bit set per start corner.
  std::vector<uint8_t> out(size_t(cw) * size_t(h + 1), 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (!data(x, y)) continue;
      if (!data(x, y - 1)) out[corner(x, y)] |= 1 << kEast;           // top edge, left to right
      if (!data(x + 1, y)) out[corner(x + 1, y)] |= 1 << kSouth;      // right edge, downwards
      if (!data(x, y + 1)) out[corner(x + 1, y + 1)] |= 1 << kWest;   // bottom edge, right to left
      if (!data(x - 1, y)) out[corner(x, y + 1)] |= 1 << kNorth;      // left edge, upwards
    }
  const std::vector<uint8_t> all = out;

  // Leaving a corner reached with heading d: a right turn first, then straight on, then a left turn. Only a saddle
  // corner (two diagonal data pixels) has two outgoing edges; turning right there stays with the same pixel,
  // which keeps diagonal-only neighbours in separate loops (4-connected data, 8-connected background).
  auto leave = [&](size_t c, int d) {
    for (int turn : {1, 0, 3}) {
      const int nd = (d + turn) & 3;
      if (all[c] & (1 << nd)) return nd;
    }
    FF_CHECK_MSG(false, "boundary edge without a successor");
    return 0;
  };

  std::vector<std::vector<DVec2>> loops;
  for (int y = 0; y <= h; ++y)
    for (int x = 0; x <= w; ++x) {
      while (out[corner(x, y)]) {
        int d = 0;
        while (!(out[corner(x, y)] & (1 << d))) ++d;
        const int start_dir = d;
        int cx = x, cy = y;
        std::vector<DVec2> loop;
        while (true) {
          loop.push_back(DVec2(cx, cy));
          out[corner(cx, cy)] &= uint8_t(~(1 << d));
          cx += kDx[d];
          cy += kDy[d];
          d = leave(corner(cx, cy), d);
          if (cx == x && cy == y && d == start_dir) break;
          FF_CHECK(out[corner(cx, cy)] & (1 << d));
        }
        loops.push_back(removeCollinear(loop));
      }
    }
  return loops;
}

Contours extractContours(const image::Image<uint8_t>& mask, const ContourOptions& options) {
  Contours result;
  for (std::vector<DVec2>& traced : traceBoundaries(mask)) {
    ContourLoop loop;
    loop.traced_area = signedArea(traced);
    loop.traced_vertices = traced.size();
    result.traced_vertices += traced.size();
    if (std::abs(loop.traced_area) < options.min_area_px) {
      ++result.dropped_loops;
      result.dropped_area += std::abs(loop.traced_area);
      continue;
    }
    loop.points = simplifyClosed(traced, options.tolerance_px);
    if (loop.points.size() < 3 || signedArea(loop.points) == 0.0) {
      ++result.dropped_loops;
      result.dropped_area += std::abs(loop.traced_area);
      continue;
    }
    result.loops.push_back(std::move(loop));
  }
  return result;
}

}  // namespace farfield::impostor
