#include "farfield/terrain/heightfield.h"

#include <limits>
#include <string>

#include "farfield/core/check.h"
#include "farfield/core/error.h"

namespace farfield::terrain {

Heightfield::Heightfield(int w, int h, double cell, float fill) : width(w), height(h), cell_x(cell), cell_y(cell) {
  FF_CHECK(w >= 0 && h >= 0);
  heights.assign(size_t(w) * size_t(h), fill);
}

float Heightfield::clampedAt(int i, int j) const {
  return at(std::clamp(i, 0, width - 1), std::clamp(j, 0, height - 1));
}

float Heightfield::sample(double x, double y) const {
  const double fx = std::clamp(x / cell_x, 0.0, double(width - 1));
  const double fy = std::clamp(y / cell_y, 0.0, double(height - 1));
  const int i0 = std::min(int(fx), std::max(width - 2, 0));
  const int j0 = std::min(int(fy), std::max(height - 2, 0));
  const double tx = fx - i0, ty = fy - j0;
  const double h00 = clampedAt(i0, j0), h10 = clampedAt(i0 + 1, j0);
  const double h01 = clampedAt(i0, j0 + 1), h11 = clampedAt(i0 + 1, j0 + 1);
  return float((h00 * (1 - tx) + h10 * tx) * (1 - ty) + (h01 * (1 - tx) + h11 * tx) * ty);
}

Vec3 Heightfield::normal(int i, int j) const {
  const int il = std::max(i - 1, 0), ir = std::min(i + 1, width - 1);
  const int jd = std::max(j - 1, 0), ju = std::min(j + 1, height - 1);
  const double dzdx = ir > il ? (at(ir, j) - at(il, j)) / ((ir - il) * cell_x) : 0.0;
  const double dzdy = ju > jd ? (at(i, ju) - at(i, jd)) / ((ju - jd) * cell_y) : 0.0;
  return glm::normalize(Vec3(float(-dzdx), float(-dzdy), 1.0f));
}

float Heightfield::minHeight() const {
  float m = std::numeric_limits<float>::max();
  for (float h : heights) m = std::min(m, h);
  return heights.empty() ? 0.0f : m;
}

float Heightfield::maxHeight() const {
  float m = std::numeric_limits<float>::lowest();
  for (float h : heights) m = std::max(m, h);
  return heights.empty() ? 0.0f : m;
}

Box3 Heightfield::bounds() const {
  Box3 box;
  if (heights.empty()) return box;
  box.expand(Vec3(0.0f, 0.0f, minHeight()));
  box.expand(Vec3(float(extentX()), float(extentY()), maxHeight()));
  return box;
}

Heightfield Heightfield::crop(int i0, int j0, int w, int h) const {
  if (i0 < 0 || j0 < 0 || w < 1 || h < 1 || i0 + w > width || j0 + h > height)
    throw Error(source, "crop " + std::to_string(w) + "x" + std::to_string(h) + " at (" + std::to_string(i0) + ", " +
                            std::to_string(j0) + ") does not fit the " + std::to_string(width) + "x" +
                            std::to_string(height) + " grid");
  Heightfield out(w, h);
  out.cell_x = cell_x;
  out.cell_y = cell_y;
  out.geo_origin = geo_origin + DVec2(i0 * cell_x, j0 * cell_y);
  out.crs = crs;
  out.source = source;
  if (!nodata.empty()) out.nodata.assign(size_t(w) * size_t(h), 0);
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      out.at(i, j) = at(i0 + i, j0 + j);
      if (!nodata.empty()) {
        out.nodata[out.index(i, j)] = nodata[index(i0 + i, j0 + j)];
        out.nodata_count += nodata[index(i0 + i, j0 + j)] ? 1 : 0;
      }
    }
  return out;
}

void fillNodata(Heightfield& hf, const std::vector<uint8_t>& mask, float far_height) {
  FF_CHECK(mask.size() == hf.size());
  size_t missing = 0;
  for (uint8_t m : mask) missing += m ? 1 : 0;
  hf.nodata = mask;
  hf.nodata_count = missing;
  if (missing == 0) return;
  if (std::isnan(far_height)) {
    if (missing == hf.size()) throw Error(hf.source, "every grid point is nodata (nothing to build a terrain from)");
    far_height = std::numeric_limits<float>::max();
    for (size_t k = 0; k < hf.size(); ++k)
      if (!mask[k]) far_height = std::min(far_height, hf.heights[k]);
  }

  // Breadth-first from the valid points: a hole's rim fills first, from valid neighbours, then the next ring from
  // the rim, so every filled height is a mean of heights that are at most one step nearer the data. Ring r's values
  // depend only on grid points within r steps: kNodataFillRings bounds that, so a window read with a margin of
  // 3 * kNodataFillRings points fills its own points as the whole grid does (DemReader).
  const int w = hf.width, h = hf.height;
  std::vector<uint8_t> known(hf.size());
  for (size_t k = 0; k < hf.size(); ++k) known[k] = mask[k] ? 0 : 1;
  std::vector<uint32_t> ring, next;
  std::vector<uint8_t> queued(hf.size(), 0);
  auto enqueueNeighbours = [&](int i, int j, std::vector<uint32_t>& out) {
    for (int dj = -1; dj <= 1; ++dj)
      for (int di = -1; di <= 1; ++di) {
        const int ni = i + di, nj = j + dj;
        if ((di == 0 && dj == 0) || ni < 0 || nj < 0 || ni >= w || nj >= h) continue;
        const size_t n = hf.index(ni, nj);
        if (!known[n] && !queued[n]) {
          queued[n] = 1;
          out.push_back(uint32_t(n));
        }
      }
  };
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i)
      if (known[hf.index(i, j)]) enqueueNeighbours(i, j, ring);
  for (int r = 1; r <= kNodataFillRings && !ring.empty(); ++r) {
    // All points of a ring take their value from points known before the ring started.
    std::vector<float> values(ring.size());
    for (size_t q = 0; q < ring.size(); ++q) {
      const int i = int(ring[q] % uint32_t(w)), j = int(ring[q] / uint32_t(w));
      double sum = 0.0;
      int count = 0;
      for (int dj = -1; dj <= 1; ++dj)
        for (int di = -1; di <= 1; ++di) {
          const int ni = i + di, nj = j + dj;
          if (ni < 0 || nj < 0 || ni >= w || nj >= h || !known[hf.index(ni, nj)]) continue;
          sum += hf.at(ni, nj);
          ++count;
        }
      FF_CHECK(count > 0);
      values[q] = float(sum / count);
    }
    next.clear();
    for (size_t q = 0; q < ring.size(); ++q) {
      hf.heights[ring[q]] = values[q];
      known[ring[q]] = 1;
    }
    for (uint32_t k : ring) enqueueNeighbours(int(k % uint32_t(w)), int(k / uint32_t(w)), next);
    ring.swap(next);
  }
  // Farther than kNodataFillRings steps from any data (open sea in a coastal DEM): flat, at far_height.
  for (size_t k = 0; k < hf.size(); ++k)
    if (!known[k]) hf.heights[k] = far_height;
}

Heightfield cropForBlocks(const Heightfield& hf, int block) {
  FF_CHECK(block >= 1 && (block & (block - 1)) == 0);
  const int a = (hf.width - 1) / block, b = (hf.height - 1) / block;
  if (a < 1 || b < 1)
    throw Error(hf.source, std::to_string(hf.width) + "x" + std::to_string(hf.height) +
                               " grid is smaller than one LOD block of " + std::to_string(block + 1) + "x" +
                               std::to_string(block + 1) + " points");
  const int w = a * block + 1, h = b * block + 1;
  return hf.crop((hf.width - w) / 2, (hf.height - h) / 2, w, h);
}

}  // namespace farfield::terrain
