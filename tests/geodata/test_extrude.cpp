// Extruded buildings: areas of walls and roofs against hand-computed values, closed surfaces (divergence theorem
// gives the volume), outward normals, pitched roofs.
#include <gtest/gtest.h>

#include <cmath>

#include "farfield/geodata/extrude.h"

using farfield::Vec2;
using farfield::Vec3;
using farfield::geodata::ExtrusionShape;
using farfield::geodata::extrudeBuilding;
using farfield::geodata::FootprintPolygon;
using farfield::geodata::RoofKind;
using farfield::scene::Mesh;

namespace {

double meshArea(const Mesh& m, double min_nz = -2.0, double max_nz = 2.0) {
  double a = 0;
  for (size_t i = 0; i < m.indices.size(); i += 3) {
    const Vec3 p0 = m.positions[m.indices[i]], p1 = m.positions[m.indices[i + 1]], p2 = m.positions[m.indices[i + 2]];
    const glm::dvec3 c = glm::cross(glm::dvec3(p1 - p0), glm::dvec3(p2 - p0));
    const double len = glm::length(c);
    if (len == 0) continue;
    const double nz = c.z / len;
    if (nz >= min_nz && nz <= max_nz) a += 0.5 * len;
  }
  return a;
}

// Signed volume enclosed by triangles (divergence theorem); the open bottom at z = 0 adds nothing.
double signedVolume(const std::vector<const Mesh*>& meshes) {
  double v = 0;
  for (const Mesh* m : meshes)
    for (size_t i = 0; i < m->indices.size(); i += 3) {
      const glm::dvec3 a(m->positions[m->indices[i]]), b(m->positions[m->indices[i + 1]]),
          c(m->positions[m->indices[i + 2]]);
      v += glm::dot(a, glm::cross(b, c)) / 6.0;
    }
  return v;
}

// Every triangle's winding agrees with its stored vertex normal.
void expectWindingMatchesNormals(const Mesh& m) {
  ASSERT_EQ(m.normals.size(), m.positions.size());
  ASSERT_EQ(m.uvs.size(), m.positions.size());
  for (size_t i = 0; i < m.indices.size(); i += 3) {
    const Vec3 p0 = m.positions[m.indices[i]], p1 = m.positions[m.indices[i + 1]], p2 = m.positions[m.indices[i + 2]];
    const Vec3 c = glm::cross(p1 - p0, p2 - p0);
    if (glm::length(c) < 1e-6f) continue;
    EXPECT_GT(glm::dot(c, m.normals[m.indices[i]]), 0.0f) << "triangle " << i / 3;
  }
}

}  // namespace

TEST(Extrude, BoxAreasVolumeAndUvs) {
  FootprintPolygon fp;
  fp.outer = {{0, 0}, {0, 20}, {10, 20}, {10, 0}};  // clockwise on purpose
  ExtrusionShape s;
  s.top = 9.0f;
  Mesh facades, roofs;
  ASSERT_TRUE(extrudeBuilding(fp, s, facades, roofs));
  EXPECT_EQ(facades.triangleCount(), 8u);
  EXPECT_EQ(roofs.triangleCount(), 2u);
  EXPECT_NEAR(meshArea(facades), 60.0 * 9.0, 1e-3);
  EXPECT_NEAR(meshArea(roofs), 200.0, 1e-3);
  // Walls + roof with the open bottom on z = 0 enclose the box: volume 10 x 20 x 9, positive = outward.
  EXPECT_NEAR(signedVolume({&facades, &roofs}), 1800.0, 1e-2);
  expectWindingMatchesNormals(facades);
  expectWindingMatchesNormals(roofs);
  // Facade v: 0 at the top, height / floor height at the bottom; u: metres / bay width.
  float max_v = 0, max_u = 0;
  for (const Vec2& uv : facades.uvs) max_v = std::max(max_v, uv.y), max_u = std::max(max_u, uv.x);
  EXPECT_NEAR(max_v, 9.0f / s.floor_height, 1e-5f);
  EXPECT_LE(max_u, 1.0f + 20.0f / s.bay_width + 1e-4f);
}

TEST(Extrude, CourtyardAndRaisedBase) {
  FootprintPolygon fp;
  fp.outer = {{0, 0}, {30, 0}, {30, 30}, {0, 30}};
  fp.holes = {{{10, 10}, {20, 10}, {20, 20}, {10, 20}}};  // counter-clockwise: fixed by the extrusion
  ExtrusionShape s;
  s.base = 4.0f;
  s.top = 16.0f;
  Mesh facades, roofs;
  ASSERT_TRUE(extrudeBuilding(fp, s, facades, roofs));
  // Roof and underside: (900 - 100) each; walls: (120 + 40) x 12.
  EXPECT_NEAR(meshArea(roofs, 0.9, 2.0), 800.0, 1e-3);
  EXPECT_NEAR(meshArea(roofs, -2.0, -0.9), 800.0, 1e-3);
  EXPECT_NEAR(meshArea(facades), 160.0 * 12.0, 1e-2);
  // Closed: volume (900 - 100) x 12.
  EXPECT_NEAR(signedVolume({&facades, &roofs}), 800.0 * 12.0, 0.5);
  expectWindingMatchesNormals(facades);
  expectWindingMatchesNormals(roofs);
  // Courtyard walls face into the courtyard: their normals point toward (15, 15).
  for (size_t i = 0; i < facades.positions.size(); ++i) {
    const Vec3 p = facades.positions[i];
    if (p.x > 5 && p.x < 25 && p.y > 5 && p.y < 25) {
      const Vec2 to_centre = Vec2(15, 15) - Vec2(p);
      EXPECT_GT(glm::dot(Vec2(facades.normals[i]), to_centre), 0.0f);
    }
  }
}

TEST(Extrude, PitchedRoofs) {
  FootprintPolygon fp;
  fp.outer = {{0, 0}, {12, 0}, {12, 8}, {0, 8}};
  ExtrusionShape s;
  s.top = 14.0f;
  s.roof = RoofKind::Gabled;
  s.roof_height = 4.0f;
  Mesh facades, roofs;
  ASSERT_TRUE(extrudeBuilding(fp, s, facades, roofs));
  // Walls to the eaves at 10 m, two gable triangles (8 x 4 / 2 each) on the short sides.
  EXPECT_NEAR(meshArea(facades), 40.0 * 10.0 + 2 * 16.0, 1e-3);
  // Two roof planes: 12 long, slope length sqrt(4^2 + 4^2).
  EXPECT_NEAR(meshArea(roofs), 2 * 12.0 * std::sqrt(32.0), 1e-3);
  // Volume: box 12 x 8 x 10 plus the prism 12 x (8 x 4 / 2).
  EXPECT_NEAR(signedVolume({&facades, &roofs}), 960.0 + 192.0, 1e-2);
  expectWindingMatchesNormals(facades);
  expectWindingMatchesNormals(roofs);
  // The ridge is at 14 m.
  float top = 0;
  for (const Vec3& p : roofs.positions) top = std::max(top, p.z);
  EXPECT_FLOAT_EQ(top, 14.0f);

  // Pyramid on a convex hexagon; a concave footprint falls back to flat.
  FootprintPolygon hex;
  for (int i = 0; i < 6; ++i) hex.outer.emplace_back(10 * std::cos(i * M_PI / 3), 10 * std::sin(i * M_PI / 3));
  s.roof = RoofKind::Pyramidal;
  EXPECT_EQ(farfield::geodata::feasibleRoof(hex, s), RoofKind::Pyramidal);
  Mesh f2, r2;
  ASSERT_TRUE(extrudeBuilding(hex, s, f2, r2));
  EXPECT_EQ(r2.triangleCount(), 6u);
  const double hex_area = 6 * (std::sqrt(3.0) / 4) * 100;
  EXPECT_NEAR(signedVolume({&f2, &r2}), hex_area * 10 + hex_area * 4 / 3, 0.05);
  FootprintPolygon l;
  l.outer = {{0, 0}, {20, 0}, {20, 10}, {10, 10}, {10, 20}, {0, 20}};
  EXPECT_EQ(farfield::geodata::feasibleRoof(l, s), RoofKind::Flat);
}

TEST(Extrude, DegenerateFootprintsAppendNothing) {
  Mesh facades, roofs;
  FootprintPolygon line;
  line.outer = {{0, 0}, {5, 5}, {10, 10}};
  EXPECT_FALSE(extrudeBuilding(line, {}, facades, roofs));
  FootprintPolygon two;
  two.outer = {{0, 0}, {5, 5}};
  EXPECT_FALSE(extrudeBuilding(two, {}, facades, roofs));
  EXPECT_TRUE(facades.positions.empty());
  EXPECT_TRUE(roofs.positions.empty());
  EXPECT_TRUE(roofs.indices.empty());
}
