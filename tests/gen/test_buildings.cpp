#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "farfield/core/error.h"
#include "farfield/gen/buildings.h"
#include "farfield/gen/textures.h"

namespace farfield::gen {
namespace {

Polygon2 rectangle(float x0, float y0, float x1, float y1) { return {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}; }

// An L-shaped block (a reflex corner) and a block with one side curved into many short edges.
Polygon2 lBlock() { return {{0, 0}, {120, 0}, {120, 60}, {60, 60}, {60, 110}, {0, 110}}; }
Polygon2 curvedBlock() {
  Polygon2 p = {{0, 0}, {100, 0}};
  for (int i = 1; i < 20; ++i) {
    const double t = i / 20.0;
    p.push_back(Vec2(float(100.0 + 25.0 * std::sin(kPi * t)), float(90.0 * t)));
  }
  p.push_back({100, 90});
  p.push_back({0, 90});
  return p;
}
Polygon2 triangleBlock() { return {{0, 0}, {140, 0}, {30, 100}}; }
// Corners cut by short chamfers (as at junctions): the lot ring swallows the short edges.
Polygon2 chamferedBlock() { return {{4, 0}, {96, 0}, {100, 4}, {100, 76}, {97, 80}, {3, 80}, {0, 77}, {0, 4}}; }

// Independent containment: every vertex inside the block or within `tol` of its boundary.
bool insideOrOn(const Polygon2& inner, const Polygon2& outer, double tol = 1e-3) {
  for (const Vec2& v : inner)
    if (!pointInPolygon(v, outer) && distanceToBoundary(v, outer) > tol) return false;
  return true;
}

double sumArea(const std::vector<Building>& buildings) {
  double a = 0.0;
  for (const Building& b : buildings) a += signedArea(b.footprint);
  return a;
}

// Count of footprints strictly containing p (more than 1 cm inside).
int coverCount(const Vec2& p, const std::vector<Building>& buildings) {
  int c = 0;
  for (const Building& b : buildings)
    if (pointInPolygon(p, b.footprint) && distanceToBoundary(p, b.footprint) > 0.01) ++c;
  return c;
}

void checkLayout(const Polygon2& block, uint64_t seed) {
  SCOPED_TRACE("seed " + std::to_string(seed));
  const BlockLayout layout = layoutBlock(block, seed);
  ASSERT_FALSE(layout.buildings.empty());
  for (const Building& b : layout.buildings) {
    EXPECT_TRUE(insideOrOn(b.footprint, block));
    EXPECT_GT(signedArea(b.footprint), 0.0);  // counter-clockwise
    EXPECT_EQ(b.walls.size(), b.footprint.size());
    EXPECT_GT(b.height, 0.0f);
    EXPECT_GE(b.top, b.height);
    EXPECT_LE(b.height, 80.0f + 3.5f);
    EXPECT_NEAR(std::fmod(b.height / b.floor_height + 0.5f, 1.0f), 0.5f, 1e-3f);  // whole floors
  }
  // No overlaps, sampled on a grid.
  const Box2 box = polygonBounds(block);
  for (float y = box.lo.y + 0.37f; y < box.hi.y; y += 2.0f)
    for (float x = box.lo.x + 0.53f; x < box.hi.x; x += 2.0f) EXPECT_LE(coverCount({x, y}, layout.buildings), 1);
  // Lots and courtyard tile the block (when there is a courtyard, nothing else is left out but dropped lots).
  const double block_area = signedArea(block);
  const double covered = sumArea(layout.buildings) + signedArea(layout.courtyard);
  if (layout.skipped_lots == 0) {
    EXPECT_NEAR(covered, block_area, 1e-3 * block_area);
  }
  EXPECT_LE(covered, block_area * (1.0 + 1e-4));
}

TEST(Buildings, LotsOfARectangularBlockTileTheRingAroundACourtyard) {
  const Polygon2 block = rectangle(0, 0, 90, 70);
  for (uint64_t seed = 1; seed <= 6; ++seed) checkLayout(block, seed);
  const BlockLayout layout = layoutBlock(block, 3);
  ASSERT_FALSE(layout.courtyard.empty());
  // The courtyard is the block inset by the lot depth: every courtyard corner is 10-20 m from the street.
  for (const Vec2& v : layout.courtyard) {
    EXPECT_GE(distanceToBoundary(v, block), 0.75 * 10.0 - 1e-3);
    EXPECT_LE(distanceToBoundary(v, block), 20.0 + 1e-3);
  }
  // Lots 8-25 m wide along the street: the perimeter (320 m) gives 320/25 .. 320/8 lots, plus at most one wider
  // remainder lot.
  EXPECT_GE(layout.buildings.size(), 320u / 34u);
  EXPECT_LE(layout.buildings.size(), 320u / 8u);
}

TEST(Buildings, IrregularBlocksStayInsideWithoutOverlaps) {
  for (uint64_t seed = 1; seed <= 4; ++seed) {
    checkLayout(lBlock(), seed);
    checkLayout(curvedBlock(), seed);
    checkLayout(triangleBlock(), seed);
    checkLayout(chamferedBlock(), seed);
  }
  // The chamfers are swallowed by the ring, not a reason to give up on lots.
  EXPECT_FALSE(layoutBlock(chamferedBlock(), 1).courtyard.empty());
}

TEST(Buildings, StreetWallsLieOnTheBlockBoundary) {
  const Polygon2 block = lBlock();
  const BlockLayout layout = layoutBlock(block, 9);
  int street = 0;
  for (const Building& b : layout.buildings)
    for (size_t i = 0; i < b.walls.size(); ++i)
      if (b.walls[i] == WallKind::Street) {
        ++street;
        const Vec2 a = b.footprint[i], c = b.footprint[(i + 1) % b.footprint.size()];
        EXPECT_LT(distanceToBoundary(a, block), 1e-3);
        EXPECT_LT(distanceToBoundary(0.5f * (a + c), block), 1e-3);
      }
  EXPECT_GT(street, 0);
}

TEST(Buildings, SmallBlockIsOneBuildingAndDegenerateBlockNone) {
  const Polygon2 small = rectangle(0, 0, 20, 25);
  const BlockLayout layout = layoutBlock(small, 1);
  ASSERT_EQ(layout.buildings.size(), 1u);
  EXPECT_NEAR(signedArea(layout.buildings[0].footprint), 500.0, 1e-3);
  EXPECT_TRUE(layout.courtyard.empty());
  EXPECT_TRUE(layoutBlock({{0, 0}, {10, 0}, {20, 0}}, 1).buildings.empty());
  EXPECT_TRUE(layoutBlock({{0, 0}, {10, 0}}, 1).buildings.empty());
}

TEST(Buildings, LayoutIsDeterministicPerSeed) {
  const BlockLayout a = layoutBlock(lBlock(), 42), b = layoutBlock(lBlock(), 42), c = layoutBlock(lBlock(), 43);
  ASSERT_EQ(a.buildings.size(), b.buildings.size());
  for (size_t i = 0; i < a.buildings.size(); ++i) {
    EXPECT_EQ(a.buildings[i].footprint, b.buildings[i].footprint);
    EXPECT_EQ(a.buildings[i].height, b.buildings[i].height);
  }
  bool differs = a.buildings.size() != c.buildings.size();
  for (size_t i = 0; !differs && i < a.buildings.size(); ++i)
    differs = a.buildings[i].footprint != c.buildings[i].footprint || a.buildings[i].height != c.buildings[i].height;
  EXPECT_TRUE(differs);
}

TEST(Buildings, HeightsHaveALongTail) {
  std::vector<float> h;
  for (uint64_t seed = 1; seed <= 150; ++seed)
    for (const Building& b : layoutBlock(rectangle(0, 0, 100, 80), seed).buildings) h.push_back(b.height);
  ASSERT_GT(h.size(), 2000u);
  std::sort(h.begin(), h.end());
  const float median = h[h.size() / 2];
  EXPECT_GE(median, 10.0f);
  EXPECT_LE(median, 25.0f);
  const size_t tall = size_t(std::count_if(h.begin(), h.end(), [](float x) { return x >= 40.0f; }));
  EXPECT_GT(tall, h.size() / 500);  // some towers ...
  EXPECT_LT(tall, h.size() / 20);   // ... but few
  EXPECT_LE(h.back(), 80.0f + 3.5f);
  const size_t mid = size_t(std::count_if(h.begin(), h.end(), [](float x) { return x >= 9.0f && x <= 26.0f; }));
  EXPECT_GT(mid, h.size() * 6 / 10);  // most 10-25 m (within a floor)
}

double triangleArea(const scene::Mesh& m, size_t t) {
  const Vec3 a = m.positions[m.indices[3 * t]], b = m.positions[m.indices[3 * t + 1]],
             c = m.positions[m.indices[3 * t + 2]];
  return 0.5 * glm::length(glm::cross(b - a, c - a));
}

// Every non-degenerate triangle is wound counter-clockwise around its vertices' (flat) normal.
void checkWinding(const scene::Mesh& m) {
  ASSERT_EQ(m.normals.size(), m.positions.size());
  ASSERT_EQ(m.uvs.size(), m.positions.size());
  for (size_t t = 0; t < m.triangleCount(); ++t) {
    const uint32_t i0 = m.indices[3 * t], i1 = m.indices[3 * t + 1], i2 = m.indices[3 * t + 2];
    ASSERT_LT(std::max({i0, i1, i2}), m.positions.size());
    const Vec3 c = glm::cross(m.positions[i1] - m.positions[i0], m.positions[i2] - m.positions[i0]);
    EXPECT_NEAR(glm::length(m.normals[i0]), 1.0f, 1e-4f);
    if (glm::length(c) < 1e-5f) continue;
    EXPECT_GT(glm::dot(c, m.normals[i0]), 0.0f) << "triangle " << t;
  }
}

Building boxBuilding(float w, float d, float h) {
  Building b;
  b.footprint = rectangle(0, 0, w, d);
  b.walls = {WallKind::Street, WallKind::Party, WallKind::Courtyard, WallKind::Party};
  b.floor_height = 3.0f;
  b.height = h;
  b.top = h;
  b.bay_width = 3.0f;
  b.balconies = true;
  return b;
}

TEST(BuildingGeometry, PlainExtrusionHasTheBoxAreas) {
  const Building b = boxBuilding(12, 18, 15);
  BuildingMeshes m;
  appendBuildingGeometry(b, 0, m);
  EXPECT_EQ(m.facades.triangleCount(), 8u);
  EXPECT_EQ(m.roofs.triangleCount(), 2u);
  double walls = 0.0, roof = 0.0;
  for (size_t t = 0; t < m.facades.triangleCount(); ++t) walls += triangleArea(m.facades, t);
  for (size_t t = 0; t < m.roofs.triangleCount(); ++t) roof += triangleArea(m.roofs, t);
  EXPECT_NEAR(walls, 2.0 * (12 + 18) * 15, 1e-3);
  EXPECT_NEAR(roof, 12.0 * 18.0, 1e-3);
  checkWinding(m.facades);
  checkWinding(m.roofs);
  // Walls face outward: each wall normal points away from the footprint centre.
  for (size_t i = 0; i < m.facades.vertexCount(); ++i) {
    const Vec3 p = m.facades.positions[i], n = m.facades.normals[i];
    EXPECT_GT(glm::dot(Vec2(n), Vec2(p) - Vec2(6, 9)), 0.0f);
  }
  // Facade uvs: one repeat per 3 m bay and per 3 m floor: the 12 m wall spans u 0..4, the height v 0..-5.
  float umax = 0.0f, vmin = 0.0f;
  for (const Vec2& uv : m.facades.uvs) umax = std::max(umax, uv.x), vmin = std::min(vmin, uv.y);
  EXPECT_NEAR(umax, 6.0f, 1e-4f);  // the 18 m walls
  EXPECT_NEAR(vmin, -5.0f, 1e-4f);
}

TEST(BuildingGeometry, TrianglesGrowWithDetail) {
  const Building b = boxBuilding(24, 15, 18);
  size_t previous = 0;
  for (int detail = 0; detail <= 4; ++detail) {
    BuildingMeshes m;
    appendBuildingGeometry(b, detail, m);
    EXPECT_GT(m.triangleCount(), previous) << "detail " << detail;
    previous = m.triangleCount();
    checkWinding(m.facades);
    checkWinding(m.roofs);
    // Nothing below the base; the roof is the top.
    Box3 box;
    for (const Vec3& p : m.facades.positions) box.expand(p);
    for (const Vec3& p : m.roofs.positions) box.expand(p);
    EXPECT_GE(box.lo.z, 0.0f - 0.2f);  // ledges may sit just below a floor line, never below the base
    EXPECT_NEAR(box.hi.z, 18.0f, 1e-4f);
  }
}

TEST(BuildingGeometry, WindowRecessesSitOnTheTexturesWindows) {
  Building b = boxBuilding(12, 10, 9);
  b.walls = {WallKind::Street, WallKind::Street, WallKind::Street, WallKind::Street};
  BuildingMeshes m;
  appendBuildingGeometry(b, 2, m);
  // Glass quads: vertices 0.25 m behind the wall plane with the wall's outward normal.
  int glass = 0;
  for (size_t i = 0; i < m.facades.vertexCount(); ++i) {
    const Vec3 p = m.facades.positions[i], n = m.facades.normals[i];
    if (std::abs(n.z) > 1e-3f) continue;
    const double depth = distanceToBoundary(Vec2(p), b.footprint);
    if (!pointInPolygon(Vec2(p), b.footprint) || std::abs(depth - 0.25) > 1e-3) continue;
    // Only the back quad carries the wall normal at that depth (reveals are perpendicular to the wall).
    const Vec2 out = Vec2(n);
    const Vec2 q = Vec2(p) + out * 0.25f;  // the point on the wall plane in front of it
    if (distanceToBoundary(q, b.footprint) > 1e-3) continue;
    ++glass;
    const float fu = m.facades.uvs[i].x - std::floor(m.facades.uvs[i].x);
    const float fv = m.facades.uvs[i].y - std::floor(m.facades.uvs[i].y);
    const bool on_u = std::abs(fu - kWindowU0) < 1e-3f || std::abs(fu - kWindowU1) < 1e-3f;
    const bool on_v = std::abs(fv - kWindowV0) < 1e-3f || std::abs(fv - kWindowV1) < 1e-3f;
    EXPECT_TRUE(on_u && on_v) << fu << " " << fv;
  }
  // 12 m walls: 4 bays, 10 m walls: 3 bays; 3 floors; 4 corners per window.
  EXPECT_EQ(glass, (2 * 4 + 2 * 3) * 3 * 4);
}

TEST(BuildingGeometry, PitchedRoofRisesToTheRidge) {
  Building b = boxBuilding(10, 14, 12);
  b.roof = RoofShape::Gable;
  b.ridge_edge = 0;
  b.roof_rise = 4.0f;
  b.top = 16.0f;
  BuildingMeshes m;
  appendBuildingGeometry(b, 1, m);
  checkWinding(m.roofs);
  checkWinding(m.facades);
  float zmax = 0.0f;
  for (const Vec3& p : m.roofs.positions) zmax = std::max(zmax, p.z);
  EXPECT_NEAR(zmax, 16.0f, 1e-4f);
  // Two slopes of 10 m x sqrt(7^2 + 4^2) m.
  double area = 0.0;
  for (size_t t = 0; t < m.roofs.triangleCount(); ++t) area += triangleArea(m.roofs, t);
  EXPECT_NEAR(area, 2.0 * 10.0 * std::sqrt(49.0 + 16.0), 1e-3);
}

TEST(Triangulation, AreasSumUpAndTrianglesAreCounterClockwise) {
  std::vector<Polygon2> polys = {lBlock(), curvedBlock(), triangleBlock(), rectangle(0, 0, 3, 2)};
  // A star (many reflex corners), given clockwise.
  Polygon2 star;
  for (int i = 0; i < 14; ++i) {
    const double a = -2.0 * kPi * i / 14.0, r = (i % 2) ? 4.0 : 10.0;
    star.push_back(Vec2(float(r * std::cos(a)), float(r * std::sin(a))));
  }
  polys.push_back(star);
  for (const Polygon2& p : polys) {
    const std::vector<uint32_t> t = triangulatePolygon(p);
    ASSERT_EQ(t.size(), 3 * (p.size() - 2));
    double sum = 0.0;
    for (size_t k = 0; k < t.size(); k += 3) {
      const double a = signedArea({p[t[k]], p[t[k + 1]], p[t[k + 2]]});
      EXPECT_GE(a, 0.0);
      sum += a;
    }
    EXPECT_NEAR(sum, std::abs(signedArea(p)), 1e-6 * std::abs(signedArea(p)) + 1e-6);
  }
}

TEST(Landmarks, FitTheBlockAndRiseAboveEveryBuilding) {
  const Polygon2 block = rectangle(0, 0, 100, 80);
  for (LandmarkKind kind : {LandmarkKind::Tower, LandmarkKind::Church}) {
    for (uint64_t seed = 1; seed <= 3; ++seed) {
      const std::optional<Building> b = makeLandmark(kind, block, seed);
      ASSERT_TRUE(b.has_value());
      EXPECT_TRUE(insideOrOn(b->footprint, block));
      EXPECT_GT(b->top, 90.0f);
      for (int detail : {0, 2}) {
        BuildingMeshes m;
        appendBuildingGeometry(*b, detail, m);
        EXPECT_EQ(m.facades.triangleCount() + m.roofs.triangleCount(), 0u);
        checkWinding(m.landmark);
        float zmax = 0.0f;
        for (const Vec3& p : m.landmark.positions) {
          zmax = std::max(zmax, p.z);
          // Cornices stand out at most 0.5 m, balconies none on landmarks.
          EXPECT_TRUE(pointInPolygon(Vec2(p), block));
        }
        EXPECT_NEAR(zmax, b->top, 1e-3f);
      }
    }
  }
  // A block too small for either.
  EXPECT_FALSE(makeLandmark(LandmarkKind::Tower, rectangle(0, 0, 12, 12), 1).has_value());
  EXPECT_FALSE(makeLandmark(LandmarkKind::Church, rectangle(0, 0, 12, 12), 1).has_value());
}

TEST(Textures, DeterministicTileableAndChecked) {
  using Maker = image::ColorImage (*)(int, uint64_t);
  for (Maker make : {&makeFacadeTexture, &makeRoofTexture, &makeGroundTexture, &makeLandmarkTexture}) {
    const image::ColorImage a = make(64, 3), b = make(64, 3), c = make(64, 4);
    ASSERT_EQ(a.width(), 64);
    EXPECT_EQ(a.pixels(), b.pixels());
    EXPECT_NE(a.pixels(), c.pixels());
    EXPECT_THROW(make(100, 1), Error);
    EXPECT_THROW(make(8, 1), Error);
    // Seamless: the jump across the wrap (last column to first) is no larger than typical neighbour jumps.
    auto colDiff = [&](int x0, int x1) {
      double d = 0.0;
      for (int y = 0; y < 64; ++y)
        for (int ch = 0; ch < 3; ++ch) d += std::abs(int(a.at(x0, y)[ch]) - int(a.at(x1, y)[ch]));
      return d;
    };
    double mean = 0.0;
    for (int x = 0; x + 1 < 64; ++x) mean += colDiff(x, x + 1) / 63.0;
    EXPECT_LE(colDiff(63, 0), 3.0 * mean + 64.0);
  }
  // The facade's window is dark glass, the wall light.
  const image::ColorImage f = makeFacadeTexture(256, 1);
  const auto glass = f.at(int(0.4f * 256), int(0.6f * 256)), wall = f.at(int(0.1f * 256), int(0.5f * 256));
  EXPECT_LT(int(glass.r) + glass.g + glass.b, int(wall.r) + wall.g + wall.b - 150);
  const CityTextures& t = cityTextures();
  ASSERT_TRUE(t.facade && t.roof && t.ground && t.landmark);
  EXPECT_EQ(t.facade->width(), 256);
}

}  // namespace
}  // namespace farfield::gen
