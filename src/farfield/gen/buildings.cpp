// Buildings of a city block from its footprint inward, to stand in for the test cities of the impostor papers
// (Sillion 1997 section 5 and Decoret 1999 section 6: Montmartre, 146 blocks of houses around a church landmark),
// with facade detail as real geometry so that polygon counts scale with the detail level.
// Here: the random numbers, ordinary buildings' geometry and appendBuildingGeometry; lots, facades, roofs and
// landmarks are in building_lots.cpp, building_facades.cpp, building_roofs.cpp and building_landmarks.cpp.
#include "farfield/gen/buildings.h"

#include <algorithm>
#include <cmath>
#include <tuple>
#include <vector>

#include "farfield/gen/building_parts.h"

namespace farfield::gen {

float Rng::normal() {
  // Box-Muller; u1 in (0, 1] so the logarithm stays finite.
  const float u1 = 1.0f - uniform();
  const float u2 = uniform();
  return std::sqrt(-2.0f * std::log(u1)) * std::cos(float(2.0 * kPi) * u2);
}

uint64_t mixSeed(uint64_t a, uint64_t b) {
  Rng rng(a ^ (b * 0xd1b54a32d192ed03ull + 0x8cb92ba72f3d8dd7ull));
  rng.next();
  return rng.next();
}

void BuildingMeshes::clear() {
  for (scene::Mesh* m : {&facades, &roofs, &landmark}) {
    m->positions.clear();
    m->normals.clear();
    m->uvs.clear();
    m->indices.clear();
  }
}

namespace {

void appendOrdinary(const Building& b, int detail, BuildingMeshes& out) {
  MeshWriter facades(out.facades), roofs(out.roofs);
  const Polygon2& p = b.footprint;
  const size_t n = p.size();
  const float z0 = b.base_z, z1 = b.base_z + b.height;
  const std::vector<uint8_t> exposed = exposedMask(b);
  const bool gable = b.roof == RoofShape::Gable && n == 4 && b.ridge_edge >= 0 && b.ridge_edge < 4;

  FacadeStyle st = styleFor(b, detail, z0);
  for (size_t i = 0; i < n; ++i) {
    FacadeStyle wall_st = st;
    if (!exposed[i]) wall_st.windows = wall_st.frames = wall_st.mullions = false;
    wall_st.balconies = detail >= 3 && b.balconies && b.walls[i] == WallKind::Street;
    emitWall(facades, p[i], p[(i + 1) % n], z0, z1, wall_st);
  }

  if (!gable) {
    emitLedges(facades, p, exposed, z0, z1, b.floor_height, detail);
    emitFlat(roofs, p, z1);
    return;
  }

  // Pitched roof: eaves along edges r and r + 2 (parallel), ridge between the midpoints of the other two edges.
  const int r = b.ridge_edge;
  const Vec2 e0 = p[size_t(r)], e1 = p[size_t(r + 1) % 4], e2 = p[size_t(r + 2) % 4], e3 = p[size_t(r + 3) % 4];
  const Vec2 m1 = 0.5f * (e1 + e2), m3 = 0.5f * (e3 + e0);
  const float zr = z1 + b.roof_rise;
  auto at = [](const Vec2& v, float z) { return Vec3(v.x, v.y, z); };
  // Gable ends (part of the facade).
  for (auto [a, c, m] : {std::tuple{e1, e2, m1}, std::tuple{e3, e0, m3}}) {
    const Vec2 e = c - a;
    const float len = glm::length(e);
    if (len <= 0.0f) continue;
    const Vec3 nrm(outwardNormal(e / len), 0.0f);
    const float v0 = -(z1 - z0) / b.floor_height, vr = -(zr - z0) / b.floor_height;
    facades.triangle(at(a, z1), at(c, z1), at(m, zr), nrm, Vec2(0.0f, v0), Vec2(len / b.bay_width, v0),
                     Vec2(0.5f * len / b.bay_width, vr));
  }
  std::vector<uint8_t> cornice = exposed;
  cornice[size_t(r + 1) % 4] = cornice[size_t(r + 3) % 4] = 0;
  emitLedges(facades, p, exposed, z0, z1, b.floor_height, detail, &cornice);
  // Slopes.
  for (auto [a, c, ma, mc] : {std::tuple{e0, e1, m3, m1}, std::tuple{e2, e3, m1, m3}}) {
    const Vec3 pa = at(a, z1), pc = at(c, z1), qc = at(mc, zr), qa = at(ma, zr);
    Vec3 nrm = glm::cross(pc - pa, qa - pa);
    const float len = glm::length(nrm);
    nrm = len > 0.0f ? nrm / len : kUp;
    if (nrm.z < 0.0f) nrm = -nrm;
    const float eave = glm::length(pc - pa) / kRoofTile, slant = glm::length(qa - pa) / kRoofTile;
    roofs.quad(pa, pc, qc, qa, nrm, Vec2(0.0f, slant), Vec2(eave, slant), Vec2(eave, 0.0f), Vec2(0.0f));
  }
}

}  // namespace

void appendBuildingGeometry(const Building& building, int detail, BuildingMeshes& out) {
  detail = std::clamp(detail, 0, 4);
  if (building.footprint.size() < 3) return;
  switch (building.landmark) {
    case LandmarkKind::Tower:
      appendTower(building, detail, out);
      break;
    case LandmarkKind::Church:
      appendChurch(building, detail, out);
      break;
    case LandmarkKind::None:
      appendOrdinary(building, detail, out);
      break;
  }
}

}  // namespace farfield::gen
