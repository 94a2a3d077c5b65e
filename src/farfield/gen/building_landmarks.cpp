// Landmarks alone in their block: a tower of setback tiers with a mast, and a church (a nave with a pitched roof,
// a front tower with a spire); where they stand (makeLandmark) and their geometry.
#include <algorithm>
#include <cmath>
#include <optional>
#include <tuple>
#include <vector>

#include "farfield/gen/building_parts.h"

namespace farfield::gen {

namespace {

Polygon2 scaledAbout(const Polygon2& p, const Vec2& c, float s) {
  Polygon2 q(p.size());
  for (size_t i = 0; i < p.size(); ++i) q[i] = c + (p[i] - c) * s;
  return q;
}

}  // namespace

void appendTower(const Building& b, int detail, BuildingMeshes& out) {
  MeshWriter w(out.landmark);
  const Polygon2& p = b.footprint;
  const Vec2 c = polygonCentroid(p);
  const float H = b.top;
  // Tiers: (scale of the footprint, top as a share of the height); the last one carries the mast.
  const float scales[3] = {1.0f, 0.74f, 0.5f};
  const float tops[3] = {b.height / H, 0.74f, 0.9f};
  FacadeStyle st = styleFor(b, detail, b.base_z);
  float z_prev = b.base_z;
  for (int t = 0; t < 3; ++t) {
    const Polygon2 tier = scaledAbout(p, c, scales[t]);
    // Tier tops on whole floors so windows fill each tier.
    const float z_top = b.base_z + std::round(tops[t] * H / b.floor_height) * b.floor_height;
    for (size_t i = 0; i < tier.size(); ++i) emitWall(w, tier[i], tier[(i + 1) % tier.size()], z_prev, z_top, st);
    const std::vector<uint8_t> all(tier.size(), 1);
    if (detail >= 1) emitBand(w, tier, all, z_top - 0.8f, z_top, 0.5f);
    if (detail >= 4)
      emitBand(w, tier, all, z_prev + 0.5f * (z_top - z_prev) - 0.2f, z_prev + 0.5f * (z_top - z_prev) + 0.2f, 0.3f);
    const Polygon2 next = t < 2 ? scaledAbout(p, c, scales[t + 1]) : scaledAbout(p, c, 0.16f);
    emitRing(w, tier, next, z_top);
    z_prev = z_top;
    if (t == 2) emitPyramid(w, next, z_top, Vec3(c.x, c.y, b.base_z + H));
  }
}

void appendChurch(const Building& b, int detail, BuildingMeshes& out) {
  MeshWriter w(out.landmark);
  const Polygon2& p = b.footprint;  // c0 c1 c2 c3, edge 0 the long side
  const Vec2 c0 = p[0], c1 = p[1], c2 = p[2], c3 = p[3];
  const float length = glm::length(c1 - c0), width = glm::length(c3 - c0);
  const Vec2 u = (c1 - c0) / length;
  const float z0 = b.base_z, hn = b.height, rise = b.roof_rise;
  const float zn = z0 + hn, zr = zn + rise;
  auto at = [](const Vec2& v, float z) { return Vec3(v.x, v.y, z); };

  // Nave: from the tower (first `width` of the length) to the far end.
  const Vec2 n0 = c0 + u * width, n3 = c3 + u * width;
  FacadeStyle nave = styleFor(b, detail, z0);
  nave.floor_h = hn / 2.0f;
  nave.bay = 5.0f;
  emitWall(w, n0, c1, z0, zn, nave);
  emitWall(w, c1, c2, z0, zn, nave);
  emitWall(w, c2, n3, z0, zn, nave);
  const Vec2 m_end = 0.5f * (c1 + c2), m_tower = 0.5f * (n0 + n3);
  {
    const Vec2 e = c2 - c1;
    const Vec3 nrm(outwardNormal(e / glm::length(e)), 0.0f);
    w.triangle(at(c1, zn), at(c2, zn), at(m_end, zr), nrm, Vec2(0.0f, 0.0f), Vec2(width / 4.0f, 0.0f),
               Vec2(width / 8.0f, -rise / 4.0f));
  }
  const Polygon2 nave_fp = {n0, c1, c2, n3};
  if (detail >= 1) emitBand(w, nave_fp, {1, 0, 1, 0}, zn - 0.6f, zn, 0.45f);
  for (auto [a, c, ma, mc] : {std::tuple{n0, c1, m_tower, m_end}, std::tuple{c2, n3, m_end, m_tower}}) {
    const Vec3 pa = at(a, zn), pc = at(c, zn), qc = at(mc, zr), qa = at(ma, zr);
    Vec3 nrm = glm::normalize(glm::cross(pc - pa, qa - pa));
    if (nrm.z < 0.0f) nrm = -nrm;
    w.quad(pa, pc, qc, qa, nrm, Vec2(0.0f), Vec2(glm::length(pc - pa) / kRoofTile, 0.0f),
           Vec2(glm::length(pc - pa) / kRoofTile, glm::length(qa - pa) / kRoofTile),
           Vec2(0.0f, glm::length(qa - pa) / kRoofTile));
  }

  // Front tower with a spire.
  const Polygon2 tower = {c0, n0, n3, c3};
  const float zt = z0 + std::max(hn + rise + 14.0f, 0.45f * b.top);
  FacadeStyle tst = styleFor(b, detail, z0);
  tst.floor_h = 6.0f;
  tst.bay = width / 3.0f;
  for (size_t i = 0; i < 4; ++i) emitWall(w, tower[i], tower[(i + 1) % 4], z0, zt, tst);
  const std::vector<uint8_t> all(4, 1);
  if (detail >= 1) emitBand(w, tower, all, zt - 1.0f, zt, 0.5f);
  if (detail >= 3) emitBand(w, tower, all, zn - 0.6f, zn, 0.45f);
  const Vec2 tc = 0.25f * (c0 + n0 + n3 + c3);
  const Polygon2 spire_base = scaledAbout(tower, tc, 0.8f);
  emitRing(w, tower, spire_base, zt);
  emitPyramid(w, spire_base, zt, Vec3(tc.x, tc.y, z0 + b.top));
}

std::optional<Building> makeLandmark(LandmarkKind kind, const Polygon2& block_in, uint64_t seed) {
  if (kind == LandmarkKind::None) return std::nullopt;
  Polygon2 block = cleanPolygon(block_in, 0.05f);
  if (block.size() < 3 || std::abs(signedArea(block)) < 1.0) return std::nullopt;
  makeCounterClockwise(block);
  Rng rng(seed);

  // The point deepest inside the block (sampled): the landmark's centre, with a circle of radius `room` free.
  const Box2 box = polygonBounds(block);
  Vec2 centre = polygonCentroid(block);
  double room = pointInPolygon(centre, block) ? distanceToBoundary(centre, block) : 0.0;
  const int samples = 24;
  for (int y = 0; y < samples; ++y)
    for (int x = 0; x < samples; ++x) {
      const Vec2 q = box.lo + box.extent() * Vec2((float(x) + 0.5f) / samples, (float(y) + 0.5f) / samples);
      if (!pointInPolygon(q, block)) continue;
      const double d = distanceToBoundary(q, block);
      if (d > room) room = d, centre = q;
    }
  // Orientation: along the block's longest edge.
  Vec2 axis(1.0f, 0.0f);
  float longest = 0.0f;
  for (size_t i = 0; i < block.size(); ++i) {
    const Vec2 e = block[(i + 1) % block.size()] - block[i];
    if (glm::length(e) > longest) longest = glm::length(e), axis = e / glm::length(e);
  }
  const Vec2 side(-axis.y, axis.x);
  const float fit = 0.95f * float(room);  // the footprint's half-diagonal must stay below this

  Building b;
  b.landmark = kind;
  auto rect = [&](float half_len, float half_wid) {
    return Polygon2{centre - axis * half_len - side * half_wid, centre + axis * half_len - side * half_wid,
                    centre + axis * half_len + side * half_wid, centre - axis * half_len + side * half_wid};
  };
  if (kind == LandmarkKind::Tower) {
    const float half = std::min(rng.uniform(11.0f, 16.0f), fit / std::sqrt(2.0f));
    if (half < 5.0f) return std::nullopt;
    b.footprint = rect(half, half);
    b.floor_height = 4.0f;
    b.bay_width = 3.2f;
    b.top = rng.uniform(130.0f, 190.0f);
    b.height = std::round(0.48f * b.top / b.floor_height) * b.floor_height;
  } else {
    float len = rng.uniform(45.0f, 65.0f), wid = 0.38f * len;
    const float half_diag = 0.5f * std::sqrt(len * len + wid * wid);
    if (half_diag > fit) {
      len *= fit / half_diag;
      wid *= fit / half_diag;
    }
    if (wid < 8.0f) return std::nullopt;
    b.footprint = rect(0.5f * len, 0.5f * wid);
    b.floor_height = 8.0f;
    b.bay_width = 5.0f;
    b.height = std::clamp(1.1f * wid, 12.0f, 22.0f);
    b.roof = RoofShape::Gable;
    b.roof_rise = 0.5f * wid;
    b.top = rng.uniform(95.0f, 120.0f);
  }
  b.walls.assign(b.footprint.size(), WallKind::Street);
  return b;
}

}  // namespace farfield::gen
