#include "farfield/scene/bvh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "farfield/scene/builtin.h"

namespace farfield::scene {
namespace {

std::vector<Box3> randomBoxes(std::mt19937& rng, int n) {
  std::uniform_real_distribution<float> pos(-200.0f, 200.0f), size(0.0f, 30.0f);
  std::vector<Box3> boxes;
  for (int i = 0; i < n; ++i) {
    const Vec3 lo(pos(rng), pos(rng), pos(rng) * 0.2f);
    const Vec3 hi = lo + Vec3(size(rng), size(rng), size(rng));
    boxes.push_back(Box3::fromPoints(lo, hi));
  }
  // Hard cases: duplicates (identical centroids), a point box, a very large box.
  for (int i = 0; i < 20; ++i) boxes.push_back(boxes[5]);
  boxes.push_back(Box3::fromPoints(Vec3(3, 3, 3), Vec3(3, 3, 3)));
  boxes.push_back(Box3::fromPoints(Vec3(-1000), Vec3(1000)));
  return boxes;
}

Camera randomCamera(std::mt19937& rng) {
  std::uniform_real_distribution<float> pos(-300.0f, 300.0f), u(0.0f, 1.0f);
  Camera c;
  c.eye = Vec3(pos(rng), pos(rng), 1.0f + 50.0f * u(rng));
  do c.at = Vec3(pos(rng), pos(rng), pos(rng) * 0.1f);
  while (glm::distance(c.at, c.eye) < 1.0f);
  c.fov_y = float(degToRad(10.0 + 100.0 * u(rng)));
  c.width = 200 + int(600 * u(rng));
  c.height = 200 + int(600 * u(rng));
  c.near_plane = 0.1f + 5.0f * u(rng);
  c.far_plane = c.near_plane + 20.0f + 400.0f * u(rng);
  return c;
}

std::vector<uint32_t> sorted(std::vector<uint32_t> v) {
  std::sort(v.begin(), v.end());
  return v;
}

TEST(Bvh, StructureInvariants) {
  std::mt19937 rng(7);
  const std::vector<Box3> boxes = randomBoxes(rng, 1000);
  std::vector<uint32_t> ids(boxes.size());
  for (size_t i = 0; i < ids.size(); ++i) ids[i] = uint32_t(i + 1);
  const Bvh bvh(boxes, ids, 4);
  EXPECT_EQ(bvh.itemCount(), boxes.size());
  std::vector<int> seen(bvh.itemCount(), 0);
  for (const Bvh::Node& n : bvh.nodes()) {
    if (n.count > 0) {
      EXPECT_LE(n.count, 4u);
      for (uint32_t k = n.first; k < n.first + n.count; ++k) ++seen.at(k);
    } else {
      ASSERT_LT(n.first + 1, bvh.nodes().size());
      for (uint32_t c : {n.first, n.first + 1}) {
        const Box3& cb = bvh.nodes()[c].bounds;
        for (int a = 0; a < 3; ++a) {
          EXPECT_LE(n.bounds.lo[a], cb.lo[a]);
          EXPECT_GE(n.bounds.hi[a], cb.hi[a]);
        }
      }
    }
  }
  for (int s : seen) EXPECT_EQ(s, 1);
  // A SAH tree over 1000 well spread boxes is far from a list.
  EXPECT_LT(bvh.depth(), 40);
  EXPECT_GT(bvh.depth(), 5);
}

TEST(Bvh, FrustumQueryEqualsBruteForce) {
  std::mt19937 rng(42);
  const std::vector<Box3> boxes = randomBoxes(rng, 800);
  std::vector<uint32_t> ids(boxes.size());
  for (size_t i = 0; i < ids.size(); ++i) ids[i] = uint32_t(1000 + 3 * i);  // ids need not be indices
  for (int leaf : {1, 4, 8}) {
    const Bvh bvh(boxes, ids, leaf);
    size_t nonempty = 0;
    for (int trial = 0; trial < 200; ++trial) {
      const Camera cam = randomCamera(rng);
      const Frustum f = Frustum::fromMatrix(cam.viewProjection());
      std::vector<uint32_t> expected;
      for (size_t i = 0; i < boxes.size(); ++i)
        if (f.intersects(boxes[i])) expected.push_back(ids[i]);
      std::vector<uint32_t> got;
      bvh.queryFrustum(f, got);
      EXPECT_EQ(sorted(got), sorted(expected)) << "leaf " << leaf << " trial " << trial;
      nonempty += (expected.size() > 1 && expected.size() < boxes.size());
    }
    EXPECT_GT(nonempty, 50u) << "the random frusta should select proper subsets";
  }
}

TEST(Bvh, BoxQueryEqualsBruteForce) {
  std::mt19937 rng(3);
  const std::vector<Box3> boxes = randomBoxes(rng, 600);
  std::vector<uint32_t> ids(boxes.size());
  for (size_t i = 0; i < ids.size(); ++i) ids[i] = uint32_t(i + 1);
  const Bvh bvh(boxes, ids);
  std::uniform_real_distribution<float> pos(-250.0f, 250.0f), size(0.0f, 80.0f);
  for (int trial = 0; trial < 300; ++trial) {
    const Vec3 lo(pos(rng), pos(rng), pos(rng) * 0.2f);
    const Box3 q = Box3::fromPoints(lo, lo + Vec3(size(rng), size(rng), size(rng)));
    std::vector<uint32_t> expected, got;
    for (size_t i = 0; i < boxes.size(); ++i)
      if (boxes[i].overlaps(q)) expected.push_back(ids[i]);
    bvh.queryBox(q, got);
    EXPECT_EQ(sorted(got), sorted(expected)) << "trial " << trial;
  }
}

TEST(Bvh, SceneAndEmptyCases) {
  const Scene s = builtinScene("cubes");
  const Bvh bvh(s);
  EXPECT_EQ(bvh.itemCount(), s.objects.size());
  std::vector<uint32_t> got;
  // A box around the centre box only (and the ground under it).
  bvh.queryBox(Box3::fromPoints(Vec3(-0.5f, -0.5f, 0.5f), Vec3(0.5f, 0.5f, 0.6f)), got);
  std::vector<uint32_t> expected;
  for (const Object& o : s.objects)
    if (o.world_bounds.overlaps(Box3::fromPoints(Vec3(-0.5f, -0.5f, 0.5f), Vec3(0.5f, 0.5f, 0.6f))))
      expected.push_back(o.id);
  EXPECT_EQ(sorted(got), sorted(expected));
  EXPECT_EQ(got.size(), 1u);  // the ground is at z = 0, below the query

  const Bvh empty;
  got.clear();
  empty.queryFrustum(Frustum::fromMatrix(Camera{}.viewProjection()), got);
  empty.queryBox(Box3::fromPoints(Vec3(-1), Vec3(1)), got);
  EXPECT_TRUE(got.empty());
  EXPECT_EQ(empty.depth(), 0);

  // Items with empty bounds are never returned.
  const Bvh with_empty({Box3{}, Box3::fromPoints(Vec3(0), Vec3(1))}, {1, 2});
  with_empty.queryBox(Box3::fromPoints(Vec3(-1e6f), Vec3(1e6f)), got);
  EXPECT_EQ(got, std::vector<uint32_t>{2});
}

}  // namespace
}  // namespace farfield::scene
