#include "farfield/scene/deforming_lod.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "farfield/core/closest_point.h"
#include "farfield/core/error.h"
#include "farfield/scene/gltf_skin.h"
#include "farfield/scene/skin.h"
#include "support/expect_error.h"
#include "support/test_support.h"

namespace farfield::scene {
namespace {

// Distance to the nearest triangle, over every triangle (apart from CGAL).
double bruteDistance(const Vec3& p, std::span<const uint32_t> indices, const std::vector<Vec3>& pose) {
  double best = std::numeric_limits<double>::infinity();
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    const Vec3& a = pose[indices[t]];
    const Vec3& b = pose[indices[t + 1]];
    const Vec3& c = pose[indices[t + 2]];
    if (glm::length(glm::cross(b - a, c - a)) == 0.0f) continue;
    best = std::min(best, double(glm::length(p - closestOnTriangle(p, a, b, c))));
  }
  return best;
}

// The same sampled two-sided distance as deformingDistance, by brute force over every triangle.
double bruteDeformingDistance(std::span<const uint32_t> full, std::span<const uint32_t> level,
                              std::span<const std::vector<Vec3>> poses) {
  double worst = 0.0;
  for (const std::vector<Vec3>& pose : poses) {
    std::vector<bool> used(pose.size(), false);
    for (uint32_t i : full) used[i] = true;
    for (size_t v = 0; v < pose.size(); ++v)
      if (used[v]) worst = std::max(worst, bruteDistance(pose[v], level, pose));
    for (size_t t = 0; t + 2 < level.size(); t += 3) {
      const Vec3 a = pose[level[t]], b = pose[level[t + 1]], c = pose[level[t + 2]];
      if (glm::length(glm::cross(b - a, c - a)) == 0.0f) continue;
      for (const Vec3& s : {(a + b + c) / 3.0f, (a + b) * 0.5f, (b + c) * 0.5f, (c + a) * 0.5f})
        worst = std::max(worst, bruteDistance(s, full, pose));
    }
  }
  return worst;
}

// An n x n grid of unit squares in the xy plane, two triangles each; vertices row-major.
std::vector<uint32_t> gridIndices(int n) {
  std::vector<uint32_t> idx;
  const auto at = [n](int x, int y) { return uint32_t(y * (n + 1) + x); };
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x)
      idx.insert(idx.end(), {at(x, y), at(x + 1, y), at(x + 1, y + 1), at(x, y), at(x + 1, y + 1), at(x, y + 1)});
  return idx;
}

// The grid flat, and the grid folded up by `angle` about the line x = n / 2 + 0.5 (a joint between two columns).
std::vector<Vec3> gridPose(int n, float angle) {
  std::vector<Vec3> pose;
  const float hinge = float(n) / 2.0f + 0.5f;
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x) {
      const float d = float(x) - hinge;
      pose.push_back(d <= 0.0f ? Vec3(float(x), float(y), 0.0f)
                               : Vec3(hinge + d * std::cos(angle), float(y), d * std::sin(angle)));
    }
  return pose;
}

std::vector<std::vector<Vec3>> walkPoses(const SkinnedModel& model, int count) {
  const int a = model.findAnimation("walk");
  const Animation& anim = model.animations[size_t(std::max(a, 0))];
  std::vector<std::vector<Vec3>> poses;
  for (int p = 0; p < count; ++p)
    poses.push_back(skinMesh(model, jointMatrices(model, &anim, anim.start + anim.duration * float(p) / float(count)))
                        .positions);
  return poses;
}

TEST(DeformingLod, LevelsOfARealSkinnedModelHoldTheirMeasuredDistanceInEveryPose) {
  FF_SHARED_FILE_OR_SKIP(man_glb, "models/CesiumMan.glb");
  const SkinnedModel man = importSkinnedModel(man_glb.string());
  const std::vector<std::vector<Vec3>> poses = walkPoses(man, 16);
  DeformingLodOptions options;
  options.triangle_ratios = {0.5, 0.25, 0.125};
  const std::vector<DeformingLevel> levels = deformingLevels(man.mesh.indices, poses, options, man.name);
  ASSERT_EQ(levels.size(), 3u);
  const size_t full = man.mesh.triangleCount();
  double previous = 0.0;
  for (size_t l = 0; l < levels.size(); ++l) {
    const std::vector<uint32_t>& idx = levels[l].indices;
    ASSERT_EQ(idx.size() % 3, 0u);
    EXPECT_LE(idx.size() / 3, size_t(std::floor(options.triangle_ratios[l] * double(full))));
    for (uint32_t i : idx) ASSERT_LT(i, man.mesh.positions.size());
    ASSERT_EQ(levels[l].source_triangles.size(), idx.size() / 3);
    for (uint32_t t : levels[l].source_triangles) ASSERT_LT(t, full);
    EXPECT_GE(levels[l].error, previous * 0.999);
    previous = levels[l].error;
  }
  // A level within a centimetre at a quarter of the triangles (a single-pose simplifier left 3.5 cm at half).
  EXPECT_LT(levels[1].error, 0.01);
  // The reported distance is the brute-force one, checked on the coarsest level over four of the poses.
  const std::vector<std::vector<Vec3>> some = {poses[0], poses[5], poses[10], poses[15]};
  EXPECT_NEAR(deformingDistance(man.mesh.indices, levels[2].indices, some),
              bruteDeformingDistance(man.mesh.indices, levels[2].indices, some), 1e-5);
}


TEST(DeformingLod, SummingThePosesKeepsWhatABendNeeds) {
  const int n = 8;
  const std::vector<uint32_t> idx = gridIndices(n);
  const std::vector<std::vector<Vec3>> flat = {gridPose(n, 0.0f)}, both = {gridPose(n, 0.0f), gridPose(n, 1.2f)};
  DeformingLodOptions options;
  options.triangle_ratios = {0.25};
  const std::vector<DeformingLevel> from_flat = deformingLevels(idx, flat, options, "grid");
  const std::vector<DeformingLevel> from_both = deformingLevels(idx, both, options, "grid");
  ASSERT_EQ(from_flat.size(), 1u);
  ASSERT_EQ(from_both.size(), 1u);
  // Flat, every merge is free, and the level is exact in the flat pose; folded, the column at the hinge matters.
  EXPECT_LT(from_flat[0].error, 1e-5);
  const double flat_in_both = deformingDistance(idx, from_flat[0].indices, both);
  EXPECT_GT(flat_in_both, 0.1);
  EXPECT_LT(from_both[0].error, 1e-4);
  EXPECT_NEAR(from_both[0].error, deformingDistance(idx, from_both[0].indices, both), 1e-9);
}

TEST(DeformingLod, APointSplitByASeamMergesEachSideIntoItsOwnSide) {
  // The grid cut along the column x = 4: that column's points have one vertex for the triangles on the left and
  // another (appended, same position) for those on the right, as a uv seam splits them.
  const int n = 8;
  std::vector<uint32_t> idx = gridIndices(n);
  std::vector<Vec3> pose = gridPose(n, 0.0f);
  const size_t base = pose.size();
  std::vector<int> side(base, 0);  // -1 left, +1 right, 0 on the seam's left copy
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x) side[size_t(y * (n + 1) + x)] = x < 4 ? -1 : (x > 4 ? 1 : 0);
  std::vector<uint32_t> copy(base, UINT32_MAX);
  for (size_t v = 0; v < base; ++v)
    if (side[v] == 0) {
      copy[v] = uint32_t(pose.size());
      pose.push_back(pose[v]);
      side.push_back(2);  // the seam's right copy
    }
  std::vector<int> tri_side;
  for (size_t t = 0; t < idx.size(); t += 3) {
    const float cx = (pose[idx[t]].x + pose[idx[t + 1]].x + pose[idx[t + 2]].x) / 3.0f;
    tri_side.push_back(cx < 4.0f ? -1 : 1);
    if (tri_side.back() > 0)
      for (size_t c = 0; c < 3; ++c)
        if (copy[idx[t + c]] != UINT32_MAX) idx[t + c] = copy[idx[t + c]];
  }
  std::vector<std::vector<Vec3>> two = {pose, pose};
  for (Vec3& p : two[1]) p.z += 0.01f * p.x * p.x;  // a gentle curve, so merges have a cost and an order
  DeformingLodOptions options;
  options.triangle_ratios = {0.5, 0.25};
  const std::vector<DeformingLevel> levels = deformingLevels(idx, two, options, "seam");
  ASSERT_FALSE(levels.empty());
  for (const DeformingLevel& level : levels)
    for (size_t t = 0; t < level.source_triangles.size(); ++t) {
      const int s = tri_side[level.source_triangles[t]];
      for (size_t c = 0; c < 3; ++c) {
        const int v = side[level.indices[3 * t + c]];
        // A left triangle holds left vertices and the seam's left copies; a right one the right side's.
        if (s < 0) {
          EXPECT_TRUE(v == -1 || v == 0) << "triangle " << t << " vertex side " << v;
        } else {
          EXPECT_TRUE(v == 1 || v == 2) << "triangle " << t << " vertex side " << v;
        }
      }
    }
  // Seam points were merged too (along the seam): fewer seam vertices are used than the column holds.
  std::vector<bool> used(pose.size(), false);
  for (uint32_t i : levels.back().indices) used[i] = true;
  size_t seam_used = 0;
  for (size_t v = 0; v < pose.size(); ++v) seam_used += used[v] && side[v] == 0 ? 1 : 0;
  EXPECT_LT(seam_used, size_t(n + 1));
}

TEST(DeformingLod, BadInputIsRefusedNamingTheSource) {
  const std::vector<uint32_t> idx = gridIndices(2);
  const std::vector<Vec3> pose = gridPose(2, 0.0f);
  const DeformingLodOptions options;
  const std::vector<std::vector<Vec3>> one = {pose};
  using farfield::test::expectErrorMentions;
  expectErrorMentions([&] { deformingLevels(idx, {}, options, "m.glb"); }, {"m.glb", "no pose"});
  const std::vector<std::vector<Vec3>> uneven = {pose, std::vector<Vec3>(pose.begin(), pose.end() - 1)};
  expectErrorMentions([&] { deformingLevels(idx, uneven, options, "m.glb"); }, {"m.glb", "pose 1 has 8 vertices"});
  std::vector<std::vector<Vec3>> nan = {pose};
  nan[0][3].y = std::nanf("");
  expectErrorMentions([&] { deformingLevels(idx, nan, options, "m.glb"); }, {"pose 0, vertex 3", "non-finite"});
  std::vector<uint32_t> past = idx;
  past[4] = 99;
  expectErrorMentions([&] { deformingLevels(past, one, options, "m.glb"); }, {"index 4 is 99"});
  const std::vector<uint32_t> partial(idx.begin(), idx.end() - 1);
  expectErrorMentions([&] { deformingLevels(partial, one, options, "m.glb"); }, {"not whole triangles"});
  DeformingLodOptions rising;
  rising.triangle_ratios = {0.25, 0.5};
  expectErrorMentions([&] { deformingLevels(idx, one, rising, "m.glb"); }, {"ratios must decrease"});
}

TEST(DeformingLod, GroupBordersStayWhereTheyAre) {
  // The grid's triangles in two groups split along a staircase (centroids left of x = 2.5), over a bowl as second
  // pose: every level keeps the left group's area (its border points move only along the border).
  const int n = 8;
  const std::vector<uint32_t> idx = gridIndices(n);
  std::vector<std::vector<Vec3>> poses = {gridPose(n, 0.0f), gridPose(n, 0.0f)};
  for (Vec3& p : poses[1]) p.z += 0.01f * (p.x * p.x + p.y * p.y);  // a bowl: every merge has a cost
  std::vector<uint32_t> groups;
  for (size_t t = 0; t < idx.size(); t += 3)
    groups.push_back(poses[0][idx[t]].x + poses[0][idx[t + 1]].x + poses[0][idx[t + 2]].x < 3.0f * 2.5f ? 0u : 1u);
  DeformingLodOptions options;
  options.triangle_ratios = {0.5, 0.25};
  // The flat area each level gives the left group: its own (the columns left of x = 2.5: a staircase of 20) when
  // its border holds.
  auto leftArea = [&](const DeformingLevel& level) {
    double area = 0.0;
    for (size_t t = 0; t < level.source_triangles.size(); ++t) {
      if (groups[level.source_triangles[t]] != 0) continue;
      const Vec3 a = poses[0][level.indices[3 * t]], b = poses[0][level.indices[3 * t + 1]],
                 c = poses[0][level.indices[3 * t + 2]];
      area += 0.5 * double(glm::length(glm::cross(b - a, c - a)));
    }
    return area;
  };
  std::vector<uint32_t> all(idx.size() / 3);
  for (size_t t = 0; t < all.size(); ++t) all[t] = uint32_t(t);
  const std::vector<DeformingLevel> grouped = deformingLevels(idx, poses, options, "grid", groups);
  const std::vector<DeformingLevel> ungrouped = deformingLevels(idx, poses, options, "grid");
  ASSERT_EQ(grouped.size(), 2u);
  ASSERT_EQ(ungrouped.size(), 2u);
  const double mesh_area = leftArea(DeformingLevel{idx, all, 0.0});
  for (const DeformingLevel& level : grouped) EXPECT_NEAR(leftArea(level), mesh_area, 1e-4);
  EXPECT_GT(std::abs(leftArea(ungrouped.back()) - mesh_area), 0.25);  // without groups the border wanders
  farfield::test::expectErrorMentions(
      [&] { deformingLevels(idx, poses, options, "grid", std::span(groups).first(3)); }, {"3 triangle groups for 128"});
}

TEST(DeformingLod, AMeshStoredAVertexPerCornerMergesByItsUvs) {
  // The grid with every triangle corner its own vertex (flat shading stores meshes so): without uvs every point is
  // split into as many sides as it has triangles and nothing merges; with the uvs (one chart) the corners of one uv
  // are one side, and the levels are those of the welded grid's quality.
  const int n = 8;
  const std::vector<uint32_t> welded = gridIndices(n);
  const std::vector<Vec3> grid = gridPose(n, 0.0f);
  std::vector<uint32_t> idx;
  std::vector<std::vector<Vec3>> poses(2);
  std::vector<Vec2> uvs;
  for (uint32_t i : welded) {
    idx.push_back(uint32_t(poses[0].size()));
    poses[0].push_back(grid[i]);
    poses[1].push_back(grid[i] + Vec3(0.0f, 0.0f, 0.01f * (grid[i].x * grid[i].x + grid[i].y * grid[i].y)));
    uvs.emplace_back(grid[i].x / float(n), grid[i].y / float(n));
  }
  DeformingLodOptions options;
  options.triangle_ratios = {0.5, 0.25};
  EXPECT_TRUE(deformingLevels(idx, poses, options, "corners").empty());
  const std::vector<DeformingLevel> levels = deformingLevels(idx, poses, options, "corners", {}, uvs);
  ASSERT_EQ(levels.size(), 2u);
  EXPECT_LE(levels[1].indices.size() / 3, welded.size() / 3 / 4);
  EXPECT_LT(levels[1].error, 0.25);
  farfield::test::expectErrorMentions(
      [&] { deformingLevels(idx, poses, options, "corners", {}, std::span(uvs).first(5)); },
      {"5 uvs for 384 vertices"});
}

}  // namespace
}  // namespace farfield::scene
