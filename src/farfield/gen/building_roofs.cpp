// Roofs: flat roofs (triangulatePolygon, ear clipping), the rings of setback tiers and spires.
#include <vector>

#include "farfield/gen/building_parts.h"

namespace farfield::gen {

void emitFlat(MeshWriter& w, const Polygon2& p, float z) {
  if (p.size() < 3) return;
  const std::vector<uint32_t> tris = triangulatePolygon(p);
  const uint32_t base = uint32_t(w.mesh().positions.size());
  const Vec2 o = p[0];
  for (const Vec2& v : p) w.vertex(Vec3(v.x, v.y, z), kUp, (v - o) / kRoofTile);
  for (size_t t = 0; t + 2 < tris.size(); t += 3) w.tri(base + tris[t], base + tris[t + 1], base + tris[t + 2]);
}

void emitPyramid(MeshWriter& w, const Polygon2& p, float z, const Vec3& apex) {
  const size_t n = p.size();
  for (size_t i = 0; i < n; ++i) {
    const Vec3 a(p[i].x, p[i].y, z), b(p[(i + 1) % n].x, p[(i + 1) % n].y, z);
    Vec3 nrm = glm::cross(b - a, apex - a);
    const float len = glm::length(nrm);
    nrm = len > 0.0f ? nrm / len : kUp;
    const float slant = glm::length(apex - 0.5f * (a + b)) / kRoofTile;
    w.triangle(a, b, apex, nrm, Vec2(kSideBandU0, 0.0f), Vec2(kSideBandU1, 0.0f),
               Vec2(0.5f * (kSideBandU0 + kSideBandU1), -slant));
  }
}

void emitRing(MeshWriter& w, const Polygon2& outer, const Polygon2& inner, float z) {
  const size_t n = outer.size();
  for (size_t i = 0; i < n; ++i) {
    const size_t j = (i + 1) % n;
    const Vec3 a(outer[i].x, outer[i].y, z), b(outer[j].x, outer[j].y, z), c(inner[j].x, inner[j].y, z),
        d(inner[i].x, inner[i].y, z);
    w.quadUv(a, b, c, d, kUp, UvRect{{kSideBandU0, 0.0f}, {kSideBandU1, 1.0f}});
  }
}

std::vector<uint32_t> triangulatePolygon(const Polygon2& polygon) {
  const size_t n = polygon.size();
  std::vector<uint32_t> out;
  if (n < 3) return out;
  out.reserve(3 * (n - 2));
  const bool ccw = signedArea(polygon) >= 0.0;
  std::vector<uint32_t> v(n);
  for (size_t i = 0; i < n; ++i) v[i] = uint32_t(ccw ? i : n - 1 - i);
  auto P = [&](uint32_t i) { return DVec2(polygon[i]); };
  auto orient = [](const DVec2& a, const DVec2& b, const DVec2& c) { return cross2(b - a, c - a); };
  size_t guard = 0;
  while (v.size() > 3 && guard < 4 * n * n) {
    ++guard;
    const size_t m = v.size();
    bool clipped = false;
    for (size_t i = 0; i < m; ++i) {
      const uint32_t ia = v[(i + m - 1) % m], ib = v[i], ic = v[(i + 1) % m];
      const DVec2 a = P(ia), b = P(ib), c = P(ic);
      if (orient(a, b, c) <= 0.0) continue;  // reflex or flat corner: not an ear
      bool blocked = false;
      for (size_t k = 0; k < m && !blocked; ++k) {
        const uint32_t iq = v[k];
        if (iq == ia || iq == ib || iq == ic) continue;
        const DVec2 q = P(iq);
        if (q == a || q == b || q == c) continue;
        blocked = orient(a, b, q) > 0.0 && orient(b, c, q) > 0.0 && orient(c, a, q) >= 0.0;
      }
      if (blocked) continue;
      out.push_back(ia);
      out.push_back(ib);
      out.push_back(ic);
      v.erase(v.begin() + std::ptrdiff_t(i));
      clipped = true;
      break;
    }
    if (!clipped) {
      // Only flat corners left (or rounding trouble): cut the least reflex corner so the loop ends.
      size_t best = 0;
      double best_o = -1e300;
      for (size_t i = 0; i < m; ++i) {
        const double o = orient(P(v[(i + m - 1) % m]), P(v[i]), P(v[(i + 1) % m]));
        if (o > best_o) best_o = o, best = i;
      }
      out.push_back(v[(best + m - 1) % m]);
      out.push_back(v[best]);
      out.push_back(v[(best + 1) % m]);
      v.erase(v.begin() + std::ptrdiff_t(best));
    }
  }
  if (v.size() == 3) {
    out.push_back(v[0]);
    out.push_back(v[1]);
    out.push_back(v[2]);
  }
  return out;
}

}  // namespace farfield::gen
