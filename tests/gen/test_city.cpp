#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>

#include "farfield/core/error.h"
#include "farfield/gen/city.h"
#include "farfield/gen/street_network.h"

namespace farfield::gen {
namespace {

// FNV-1a over raw bytes.
struct Hasher {
  uint64_t h = 1469598103934665603ull;
  void bytes(const void* data, size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
  }
  template <class T>
  void vec(const std::vector<T>& v) {
    const uint64_t n = v.size();
    bytes(&n, sizeof n);
    if (!v.empty()) bytes(v.data(), v.size() * sizeof(T));
  }
};

uint64_t sceneHash(const scene::Scene& s) {
  Hasher h;
  for (const scene::Mesh& m : s.meshes) {
    h.vec(m.positions);
    h.vec(m.normals);
    h.vec(m.uvs);
    h.vec(m.indices);
  }
  for (const scene::Object& o : s.objects) {
    h.vec(o.footprint);
    for (const scene::Part& p : o.parts) h.bytes(&p, sizeof p);
  }
  return h.h;
}

CityOptions small(int blocks, uint64_t seed, int detail, bool hill = false,
                  ObjectGrouping objects = ObjectGrouping::Blocks) {
  CityOptions o;
  o.blocks = blocks;
  o.seed = seed;
  o.detail = detail;
  o.hill = hill;
  o.objects = objects;
  return o;
}

// Cities shared by several tests (generation takes a moment).
const City& perBuilding() {
  static const City city = generateCity(small(24, 5, 1, false, ObjectGrouping::Buildings));
  return city;
}
const City& perBlock() {
  static const City city = generateCity(small(24, 5, 1, false, ObjectGrouping::Blocks));
  return city;
}
const City& hillCity() {
  static const City city = generateCity(small(30, 2, 0, true, ObjectGrouping::Buildings));
  return city;
}

bool insideOrOn(const std::vector<Vec2>& inner, const Polygon2& outer, double tol) {
  for (const Vec2& v : inner)
    if (!pointInPolygon(v, outer) && distanceToBoundary(v, outer) > tol) return false;
  return true;
}

bool isLandmark(const scene::Scene& s, const scene::Object& o) {
  for (const scene::Part& p : o.parts)
    if (s.materials[p.material].name == "landmark stone") return true;
  return false;
}

TEST(City, SameSeedSameCityOtherSeedOtherCity) {
  const City a = generateCity(small(20, 7, 1)), b = generateCity(small(20, 7, 1)), c = generateCity(small(20, 8, 1));
  EXPECT_EQ(sceneHash(a.scene), sceneHash(b.scene));
  EXPECT_EQ(a.object_block, b.object_block);
  EXPECT_NE(sceneHash(a.scene), sceneHash(c.scene));
}

TEST(City, TrianglesGrowStrictlyWithDetail) {
  uint64_t previous = 0;
  for (int detail = 0; detail <= 4; ++detail) {
    const City city = generateCity(small(10, 3, detail));
    const uint64_t t = city.scene.triangleCount();
    EXPECT_GT(t, previous) << "detail " << detail;
    previous = t;
  }
}

TEST(City, BuildingFootprintsLieInTheirBlocks) {
  const City& city = perBuilding();
  ASSERT_EQ(city.object_block.size(), city.scene.objects.size());
  EXPECT_EQ(city.object_block[0], -1);
  std::map<int32_t, Polygon2> block_polygons;
  size_t checked = 0;
  for (size_t i = 1; i < city.scene.objects.size(); ++i) {
    const scene::Object& o = city.scene.objects[i];
    const int32_t face = city.object_block[i];
    ASSERT_GT(face, 0);
    ASSERT_LT(size_t(face), city.streets.faceCount());
    if (!block_polygons.count(face)) block_polygons[face] = buildableFootprint(city.streets, uint32_t(face));
    const Polygon2& block = block_polygons[face];
    ASSERT_GE(block.size(), 3u);
    ASSERT_GE(o.footprint.size(), 3u);
    EXPECT_TRUE(insideOrOn(o.footprint, block, 0.01)) << o.name;
    ++checked;
  }
  EXPECT_GT(checked, 24u * 5u);
  EXPECT_EQ(checked, city.buildings);
}

TEST(City, BuildingsOfABlockDoNotOverlap) {
  const City& city = perBuilding();
  std::map<int32_t, std::vector<const scene::Object*>> by_block;
  for (size_t i = 1; i < city.scene.objects.size(); ++i)
    by_block[city.object_block[i]].push_back(&city.scene.objects[i]);
  size_t samples = 0;
  for (const auto& [face, objects] : by_block) {
    const Box2 box = polygonBounds(buildableFootprint(city.streets, uint32_t(face)));
    for (float y = box.lo.y + 0.41f; y < box.hi.y; y += 2.5f)
      for (float x = box.lo.x + 0.29f; x < box.hi.x; x += 2.5f) {
        int cover = 0;
        for (const scene::Object* o : objects)
          if (pointInPolygon({x, y}, o->footprint) && distanceToBoundary({x, y}, o->footprint) > 0.01) ++cover;
        EXPECT_LE(cover, 1) << "block " << face << " at " << x << ", " << y;
        samples += cover;
      }
  }
  EXPECT_GT(samples, 1000u);
}

TEST(City, BlockObjectsKeepTheBlockFootprintAndAtMostThreeParts) {
  const City& city = perBlock();
  for (size_t i = 1; i < city.scene.objects.size(); ++i) {
    const scene::Object& o = city.scene.objects[i];
    EXPECT_LE(o.parts.size(), 3u);
    const Polygon2 block = buildableFootprint(city.streets, uint32_t(city.object_block[i]));
    EXPECT_EQ(o.footprint, block);
    // The object's geometry stands on its footprint: at detail 1 only cornices stand out, 0.4 m, up to 4x that at
    // the mitre of a sharp corner.
    const Box2 fb = polygonBounds(block);
    EXPECT_GE(o.world_bounds.lo.x, fb.lo.x - 1.65f);
    EXPECT_LE(o.world_bounds.hi.x, fb.hi.x + 1.65f);
    EXPECT_GE(o.world_bounds.lo.y, fb.lo.y - 1.65f);
    EXPECT_LE(o.world_bounds.hi.y, fb.hi.y + 1.65f);
  }
  EXPECT_NO_THROW(city.scene.validate("city"));
  // The ground covers every block.
  const Box3 g = city.scene.objects[0].world_bounds;
  for (const scene::Object& o : city.scene.objects) {
    EXPECT_LE(g.lo.x, o.world_bounds.lo.x);
    EXPECT_GE(g.hi.y, o.world_bounds.hi.y);
  }
}

TEST(City, HeightsArePositiveAndLandmarksStandOut) {
  const City& city = perBuilding();
  std::vector<float> ordinary, landmarks;
  for (size_t i = 1; i < city.scene.objects.size(); ++i) {
    const scene::Object& o = city.scene.objects[i];
    const float h = o.world_bounds.hi.z - o.world_bounds.lo.z;
    EXPECT_GT(h, 2.0f) << o.name;
    EXPECT_NEAR(o.world_bounds.lo.z, 0.0f, 1e-4f) << o.name;  // flat city: everything stands on z = 0
    (isLandmark(city.scene, o) ? landmarks : ordinary).push_back(h);
  }
  ASSERT_GE(landmarks.size(), 2u);  // a church and a tower at least
  EXPECT_EQ(landmarks.size(), city.landmarks);
  std::sort(ordinary.begin(), ordinary.end());
  const float p95 = ordinary[size_t(0.95 * double(ordinary.size() - 1))];
  for (float h : landmarks) EXPECT_GT(h, p95);
  for (float h : landmarks) EXPECT_GT(h, ordinary.back());  // taller than everything
}

TEST(City, PerBuildingObjectsHoldTheSameTriangles) {
  const City& blocks = perBlock();
  const City& buildings = perBuilding();
  EXPECT_GT(buildings.scene.objects.size(), blocks.scene.objects.size());
  EXPECT_EQ(buildings.scene.triangleCount(), blocks.scene.triangleCount());
  EXPECT_EQ(buildings.buildings, blocks.buildings);
}

TEST(City, OptionsOutOfRangeThrow) {
  EXPECT_THROW(generateCity(small(9, 1, 1)), Error);
  EXPECT_THROW(generateCity(small(200001, 1, 1)), Error);
  EXPECT_THROW(generateCity(small(20, 1, -1)), Error);
  EXPECT_THROW(generateCity(small(20, 1, 5)), Error);
  try {
    generateCity(small(3, 1, 1));
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("blocks"), std::string::npos);
  }
}

// The ground mesh stays within 0.3 m of the ground's function between its vertices (triangle centroids), and every
// building reaches below the ground under each footprint corner and rises above it.
void expectStandingOnTheGround(const City& city, const CityOptions& options) {
  const scene::Mesh& ground = city.scene.meshes[city.scene.objects[0].parts[0].mesh];
  for (size_t t = 0; t < ground.triangleCount(); ++t) {
    const Vec3 c = (ground.positions[ground.indices[3 * t]] + ground.positions[ground.indices[3 * t + 1]] +
                    ground.positions[ground.indices[3 * t + 2]]) /
                   3.0f;
    EXPECT_NEAR(c.z, cityGroundHeight(options, city.bounds, Vec2(c)), 0.3f);
  }
  for (size_t i = 1; i < city.scene.objects.size(); ++i) {
    const scene::Object& o = city.scene.objects[i];
    for (const Vec2& v : o.footprint) {
      const float g = cityGroundHeight(options, city.bounds, v);
      EXPECT_LE(o.world_bounds.lo.z, g) << o.name;
      EXPECT_GT(o.world_bounds.hi.z, g + 2.0f) << o.name;
    }
  }
}

TEST(City, HillRaisesGroundAndBuildingsStandInIt) {
  const City& city = hillCity();
  CityOptions options = small(30, 2, 0, true);
  const Vec2 centre = city.bounds.center();
  const float top = cityGroundHeight(options, city.bounds, centre);
  EXPECT_GT(top, 10.0f);
  EXPECT_EQ(cityGroundHeight(small(30, 2, 0, false), city.bounds, centre), 0.0f);
  EXPECT_EQ(cityGroundHeight(options, city.bounds, city.bounds.lo), 0.0f);  // flat at the edge
  // The ground mesh follows the height function at its vertices.
  const scene::Mesh& ground = city.scene.meshes[city.scene.objects[0].parts[0].mesh];
  float zmax = 0.0f;
  for (const Vec3& p : ground.positions) {
    EXPECT_NEAR(p.z, cityGroundHeight(options, city.bounds, Vec2(p)), 1e-3f);
    zmax = std::max(zmax, p.z);
  }
  EXPECT_GT(zmax, 0.95f * top);
  expectStandingOnTheGround(city, options);
}

// Any ground (a terrain, gen city --terrain): the same promises for a tilted, rolling function, given relative to
// the centre of the city's bounds; a hill and a ground together, or a bad cell, are errors.
TEST(City, BuildingsStandOnAGivenGround) {
  CityOptions options = small(30, 2, 0, false, ObjectGrouping::Buildings);
  options.ground = [](Vec2 p) { return 0.04f * p.x + 6.0f * std::sin(p.y / 50.0f); };
  options.ground_cell = 5.0f;
  const City city = generateCity(options);
  EXPECT_EQ(cityGroundHeight(options, city.bounds, city.bounds.center()), 0.0f);
  EXPECT_NEAR(cityGroundHeight(options, city.bounds, city.bounds.center() + Vec2(100.0f, 0.0f)), 4.0f, 1e-4f);
  const scene::Mesh& ground = city.scene.meshes[city.scene.objects[0].parts[0].mesh];
  for (const Vec3& p : ground.positions) EXPECT_NEAR(p.z, cityGroundHeight(options, city.bounds, Vec2(p)), 1e-3f);
  EXPECT_GT(ground.positions.size(), 1000u);  // cells of about 5 m, not the flat ground's two triangles
  expectStandingOnTheGround(city, options);

  CityOptions both = options;
  both.hill = true;
  EXPECT_THROW(generateCity(both), Error);
  options.ground_cell = 0.0f;
  EXPECT_THROW(generateCity(options), Error);
}

TEST(City, StreetsPathNextToTheGlb) {
  EXPECT_EQ(streetsPathFor("out/city.glb"), "out/city.streets.json");
  EXPECT_EQ(streetsPathFor("CITY.GLB"), "CITY.streets.json");
  EXPECT_EQ(streetsPathFor("city"), "city.streets.json");
  EXPECT_EQ(streetsPathFor(".glb"), ".glb.streets.json");
}

}  // namespace
}  // namespace farfield::gen
