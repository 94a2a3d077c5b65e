// gen/vegetation.h: trees are seeded and stay inside their crown, street trees stand outside the blocks along their
// edges, park trees inside their park and apart, and the city's tree option adds trees without touching the city
// it leaves off.
#include "farfield/gen/vegetation.h"

#include <gtest/gtest.h>

#include "farfield/core/error.h"
#include "farfield/gen/city.h"

namespace farfield::gen {
namespace {

TEST(Vegetation, TreeIsSeededAndInsideItsCrown) {
  TreeOptions o;
  o.leaves = 500;
  const TreeMeshes a = makeTree(o, 7, Vec3(10, 20, 3));
  const TreeMeshes b = makeTree(o, 7, Vec3(10, 20, 3));
  const TreeMeshes c = makeTree(o, 8, Vec3(10, 20, 3));
  EXPECT_EQ(a.crown.triangleCount(), 500u);
  EXPECT_EQ(a.crown.positions, b.crown.positions);
  EXPECT_NE(a.crown.positions, c.crown.positions);
  a.crown.validate("crown");
  a.trunk.validate("trunk");
  const Vec3 centre(10, 20, 3 + 0.62f * o.height);
  for (const Vec3& p : a.crown.positions) {
    const Vec3 d = (p - centre) / Vec3(o.crown_radius + o.leaf_size, o.crown_radius + o.leaf_size,
                                       0.38f * o.height + o.leaf_size);
    EXPECT_LE(glm::length(d), 1.0f);
  }
  EXPECT_GE(a.trunk.bounds.lo.z, 3.0f - 0.31f);
  o.leaves = 0;
  EXPECT_THROW(makeTree(o, 1, Vec3(0)), Error);
}

TEST(Vegetation, StreetTreesLineTheBlocksOutside) {
  const Polygon2 square{Vec2(0, 0), Vec2(100, 0), Vec2(100, 60), Vec2(0, 60)};
  const std::vector<Vec2> sites = streetTreeSites(std::span(&square, 1), 18.0f, 2.0f);
  // Per edge: floor((len - 8) / 18) + 1 trees: 6 + 3 + 6 + 3.
  EXPECT_EQ(sites.size(), 18u);
  for (const Vec2& p : sites) {
    EXPECT_FALSE(pointInPolygon(p, square));
    EXPECT_NEAR(distanceToBoundary(p, square), 2.0, 1e-4);
  }
}

TEST(Vegetation, ParkTreesStayInsideAndApart) {
  const Polygon2 park{Vec2(0, 0), Vec2(80, 0), Vec2(80, 80), Vec2(0, 80)};
  const std::vector<Vec2> sites = parkTreeSites(park, 1.0f / 100.0f, 5.0f, 3.0f, 3);
  EXPECT_GT(sites.size(), 40u);
  for (size_t i = 0; i < sites.size(); ++i) {
    EXPECT_TRUE(pointInPolygon(sites[i], park));
    EXPECT_GE(distanceToBoundary(sites[i], park), 3.0);
    for (size_t j = 0; j < i; ++j) EXPECT_GE(glm::length(sites[i] - sites[j]), 5.0f);
  }
}

TEST(Vegetation, CityTreesAreAnOptionOutsideTheBuildings) {
  CityOptions o;
  o.blocks = 12;
  o.seed = 4;
  const City plain = generateCity(o);
  EXPECT_EQ(plain.trees, 0u);
  o.trees = true;
  o.park_share = 0.3f;
  const City green = generateCity(o);
  EXPECT_GT(green.trees, 50u);
  EXPECT_GT(green.parks, 0u);
  EXPECT_EQ(green.object_block.size(), green.scene.objects.size());
  size_t trees = 0;
  for (const scene::Object& obj : green.scene.objects) trees += obj.name == "tree";
  EXPECT_EQ(trees, green.trees);
  // Without parks the buildings are the same as the plain city's, and the trees stand outside their footprints.
  o.park_share = 0.0f;
  const City rows = generateCity(o);
  EXPECT_EQ(rows.parks, 0u);
  EXPECT_EQ(rows.buildings, plain.buildings);
  EXPECT_EQ(rows.scene.objects.size(), plain.scene.objects.size() + rows.trees);
  for (size_t i = 0; i < rows.trees; ++i) {
    const scene::Object& tree = rows.scene.objects[plain.scene.objects.size() + i];
    ASSERT_EQ(tree.name, "tree");
    for (size_t j = 1; j < plain.scene.objects.size(); ++j)
      EXPECT_FALSE(pointInPolygon(Vec2(tree.world_bounds.center()), plain.scene.objects[j].footprint));
  }
}

TEST(Vegetation, ForestStandsOnItsGround) {
  ForestOptions o;
  o.size = 120.0f;
  o.trees = 60;
  o.tree.leaves = 50;
  const scene::Scene forest = generateForest(o);
  EXPECT_EQ(forest.objects.size(), 61u);
  for (size_t i = 1; i < forest.objects.size(); ++i) {
    const Box3& b = forest.objects[i].world_bounds;
    const float g = forestGroundHeight(o, Vec2(b.center()));
    EXPECT_NEAR(b.lo.z, g - 0.3f, 0.5f);
  }
  o.trees = 0;
  EXPECT_THROW(generateForest(o), Error);
}

}  // namespace
}  // namespace farfield::gen
