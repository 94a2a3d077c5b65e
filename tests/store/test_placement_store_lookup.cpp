// Placement database CPV lookup (lookupCpv, lookupLeaf): agrees with a brute-force scan over random view spaces,
// eyes on split planes and directions on cube edges included.
#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <random>
#include <vector>

#include "farfield/store/placement_store.h"
#include "store/placement_store_fixture.h"

namespace farfield::store {
namespace {

using placement_test::randomViewSpace;

TEST(PlacementStoreTest, LookupCpvAgreesWithABruteForceScan) {
  size_t views = 0, found = 0, ties = 0;
  for (uint32_t seed = 1; seed <= 30; ++seed) {
    std::mt19937 rng(seed);
    PlacementIndex index;
    randomViewSpace(rng, index, 1 + int(seed % 7), {});
    const auto u = [&](double lo, double hi) { return float(std::uniform_real_distribution<double>(lo, hi)(rng)); };
    const Box3& vs = index.view_space;
    const Vec3 margin = 0.1f * vs.extent();
    for (int k = 0; k < 3000; ++k) {
      Vec3 eye(u(vs.lo.x - margin.x, vs.hi.x + margin.x), u(vs.lo.y - margin.y, vs.hi.y + margin.y),
               u(vs.lo.z - margin.z, vs.hi.z + margin.z));
      // Some eyes exactly on a split plane (on two regions: the BSP takes the lower child).
      bool on_plane = false;
      if (k % 5 == 0 && index.nodes.size() > 1) {
        const StoredViewSpaceNode& lower = index.nodes[1 + rng() % (index.nodes.size() - 1)];
        const int axis = int(rng() % 3);
        eye[axis] = rng() % 2 ? lower.box.lo[axis] : lower.box.hi[axis];
        on_plane = true;
      }
      Vec3 dir(u(-1, 1), u(-1, 1), u(-1, 1));
      if (k % 7 == 0) dir[int(rng() % 3)] = 0.0f;  // on a cube edge between faces
      if (glm::length(dir) < 1e-3f) continue;
      // Brute force: every CPV whose region holds the eye and whose VDI holds the direction.
      std::vector<uint32_t> holding;
      bool on_boundary = on_plane;
      for (uint32_t c = 0; c < index.cpvs.size(); ++c) {
        if (!index.cpvs[c].region.contains(eye) || !index.cpvs[c].vdi.contains(dir)) continue;
        holding.push_back(c);
        for (int a = 0; a < 3; ++a)
          on_boundary |= eye[a] == index.cpvs[c].region.lo[a] || eye[a] == index.cpvs[c].region.hi[a];
      }
      const std::optional<uint32_t> got = lookupCpv(index, eye, dir);
      ++views;
      // The leaf holding the eye: a leaf whose box holds it (brute force over the nodes), none outside the space.
      const std::optional<uint32_t> leaf = lookupLeaf(index, eye);
      bool in_some_leaf = false;
      for (const StoredViewSpaceNode& n : index.nodes) in_some_leaf |= n.children[0] < 0 && n.box.contains(eye);
      EXPECT_EQ(leaf.has_value(), in_some_leaf) << "seed " << seed << " view " << k;
      if (leaf) {
        EXPECT_LT(index.nodes[*leaf].children[0], 0);
        EXPECT_TRUE(index.nodes[*leaf].box.contains(eye));
      }
      if (holding.empty()) {
        EXPECT_FALSE(got.has_value()) << "seed " << seed << " view " << k << ": found " << *got;
        continue;
      }
      if (on_boundary) {
        // On a face shared by two regions: any CPV holding the view (or none, when the lower region has no CPV
        // for this direction) is right.
        ++ties;
        if (got) {
          EXPECT_NE(std::find(holding.begin(), holding.end(), *got), holding.end()) << "seed " << seed;
        }
        continue;
      }
      ASSERT_TRUE(got.has_value()) << "seed " << seed << " view " << k << ": brute force finds cpv " << holding[0];
      EXPECT_EQ(*got, holding[0]) << "seed " << seed << " view " << k;
      ++found;
    }
  }
  EXPECT_GT(found, 5000u);
  EXPECT_GT(ties, 1000u);
  EXPECT_GT(views - found - ties, 5000u);  // views in no CPV
  PlacementIndex empty;
  EXPECT_FALSE(lookupCpv(empty, Vec3(0.0f), Vec3(1.0f, 0.0f, 0.0f)).has_value());
}

}  // namespace
}  // namespace farfield::store
