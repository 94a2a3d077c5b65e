#include "farfield/placement/object_hierarchy.h"

#include <gtest/gtest.h>

#include <map>
#include <random>
#include <set>

#include "farfield/core/error.h"
#include "farfield/scene/builtin.h"

using namespace farfield;
using namespace farfield::placement;

namespace {

std::vector<HierarchyItem> randomItems(uint32_t seed, int n) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  std::vector<HierarchyItem> items;
  for (int k = 0; k < n; ++k) {
    const Vec3 lo(1000.0f * uni(rng), 600.0f * uni(rng), 0.0f);
    items.push_back({uint32_t(k + 1), Box3::fromPoints(lo, lo + Vec3(5.0f + 20.0f * uni(rng), 5.0f + 20.0f * uni(rng), 40.0f * uni(rng))),
                     uint64_t(rng() % 5000)});
  }
  return items;
}

}  // namespace

// Every node against a recount from its objects; children partition their parent; ancestry against parent walks.
TEST(ObjectHierarchy, NodesAgreeWithTheirObjects) {
  std::vector<HierarchyItem> items = randomItems(1, 700);
  items[10].bounds = Box3{};  // skipped
  items[20].bounds.lo.x = NAN;
  const ObjectHierarchy h = ObjectHierarchy::build(items);
  EXPECT_EQ(h.skipped(), 2u);
  std::map<uint32_t, const HierarchyItem*> by_id;
  for (const HierarchyItem& it : items) by_id[it.id] = &it;
  const auto& nodes = h.nodes();
  ASSERT_FALSE(nodes.empty());
  EXPECT_EQ(h.objects(0).size(), 698u);
  int max_level = 0;
  std::multiset<uint32_t> in_leaves;
  for (int n = 0; n < int(nodes.size()); ++n) {
    const HierarchyNode& node = nodes[size_t(n)];
    max_level = std::max(max_level, node.level);
    Box3 bounds;
    uint64_t triangles = 0;
    for (uint32_t id : h.objects(n)) {
      bounds.expand(by_id.at(id)->bounds);
      triangles += by_id.at(id)->triangles;
    }
    EXPECT_EQ(node.bounds.lo, bounds.lo);
    EXPECT_EQ(node.bounds.hi, bounds.hi);
    EXPECT_EQ(node.triangles, triangles);
    if (node.children[0] < 0) {
      for (uint32_t id : h.objects(n)) in_leaves.insert(id);
      continue;
    }
    const auto left = h.objects(node.children[0]), right = h.objects(node.children[1]);
    EXPECT_LE(std::abs(int(left.size()) - int(right.size())), 1);  // median split
    std::set<uint32_t> parent_set(h.objects(n).begin(), h.objects(n).end()), union_set(left.begin(), left.end());
    union_set.insert(right.begin(), right.end());
    EXPECT_EQ(parent_set, union_set);
    // Close objects first: along the split axis the left centres are not beyond the right ones.
    Box3 centres;
    for (uint32_t id : h.objects(n)) centres.expand(by_id.at(id)->bounds.center());
    const int axis = centres.longestAxis();
    float left_max = -1e30f, right_min = 1e30f;
    for (uint32_t id : left) left_max = std::max(left_max, by_id.at(id)->bounds.center()[axis]);
    for (uint32_t id : right) right_min = std::min(right_min, by_id.at(id)->bounds.center()[axis]);
    EXPECT_LE(left_max, right_min);
    EXPECT_EQ(nodes[size_t(node.children[0])].parent, n);
  }
  EXPECT_EQ(max_level, 8);  // 9 levels by default
  EXPECT_EQ(in_leaves.size(), 698u);
  EXPECT_EQ(std::set<uint32_t>(in_leaves.begin(), in_leaves.end()).size(), 698u);

  const std::vector<int> parent = h.parents();
  for (int a = 0; a < int(nodes.size()); a += 3)
    for (int b = 0; b < int(nodes.size()); ++b) {
      bool walk = false;
      for (int at = parent[size_t(b)]; at >= 0; at = parent[size_t(at)]) walk = walk || at == a;
      ASSERT_EQ(h.isAncestor(a, b), walk) << a << " " << b;
    }
  EXPECT_NEAR(h.size(0), glm::length(nodes[0].bounds.extent()), 1e-3f);
}

TEST(ObjectHierarchy, LevelsAndLeafSize) {
  const std::vector<HierarchyItem> items = randomItems(2, 40);
  const ObjectHierarchy one = ObjectHierarchy::build(items, {.max_levels = 1});
  EXPECT_EQ(one.nodes().size(), 1u);
  const ObjectHierarchy deep = ObjectHierarchy::build(items, {.max_levels = 20});
  for (const HierarchyNode& n : deep.nodes()) {
    if (n.children[0] < 0) {
      EXPECT_EQ(n.count, 1u);  // split down to single objects
    }
  }
  const ObjectHierarchy coarse = ObjectHierarchy::build(items, {.max_levels = 20, .min_objects_to_split = 8});
  for (const HierarchyNode& n : coarse.nodes()) {
    if (n.children[0] >= 0) {
      EXPECT_GE(n.count, 8u);
    }
  }
  EXPECT_TRUE(ObjectHierarchy::build(std::vector<HierarchyItem>{}).nodes().empty());
  EXPECT_THROW(ObjectHierarchy::build(items, {.max_levels = 0}), Error);
  EXPECT_THROW(ObjectHierarchy::build(items, {.max_levels = 9, .min_objects_to_split = 1}), Error);
}

TEST(ObjectHierarchy, FromScene) {
  const scene::Scene s = scene::builtinScene("cubes");
  const ObjectHierarchy h = ObjectHierarchy::build(s);
  ASSERT_FALSE(h.nodes().empty());
  EXPECT_EQ(h.nodes()[0].triangles, s.triangleCount());
  EXPECT_EQ(h.objects(0).size() + h.skipped(), s.objects.size());
}
