// The arena's simplified levels (gpu/arena_mesh.h, simplifiedMesh; gpu/scene_arena.h, partLodErrorPx): the error a
// level states bounds the distance, found by brute force, from every vertex of the full mesh to the simplified
// surface and from the simplified surface back to the full one; and a part drawn simplified under a bound of p pixels
// moves no vertex of it by more than p pixels for that camera.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "farfield/core/closest_point.h"
#include "farfield/gpu/arena_mesh.h"
#include "farfield/gpu/gpu_culler.h"
#include "farfield/gpu/render_target.h"
#include "farfield/scene/builtin.h"
#include "gpu/gpu_fixture.h"

namespace farfield::gpu {
namespace {

using test::GpuTest;

double distanceToSurface(const Vec3& p, const std::vector<Vec3>& positions, const std::vector<uint32_t>& indices) {
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i + 2 < indices.size(); i += 3) {
    const Vec3 q = closestOnTriangle(p, positions[indices[i]], positions[indices[i + 1]], positions[indices[i + 2]]);
    best = std::min(best, double(glm::length(q - p)));
  }
  return best;
}

// A height field of gentle hills over [0, 40]^2 (n x n quads): a surface simplification can flatten a lot of.
scene::Mesh hills(int n) {
  scene::Mesh mesh;
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x) {
      const float fx = 40.0f * float(x) / float(n), fy = 40.0f * float(y) / float(n);
      mesh.positions.emplace_back(fx, fy, 2.0f * std::sin(fx * 0.2f) * std::cos(fy * 0.15f) + 0.05f * std::sin(fx * 3.0f));
      mesh.normals.emplace_back(0.0f, 0.0f, 1.0f);
    }
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const uint32_t i = uint32_t(y * (n + 1) + x);
      mesh.indices.insert(mesh.indices.end(), {i, i + 1, i + uint32_t(n) + 2, i, i + uint32_t(n) + 2, i + uint32_t(n) + 1});
    }
  return mesh;
}

// The largest brute-force distance (every triangle tried) from the full mesh's vertices to the simplified surface, and
// from points of the simplified triangles (corners, edge midpoints, centroid) to the full surface.
double twoSidedError(const scene::Mesh& mesh, const std::vector<uint32_t>& simplified) {
  double worst = 0.0;
  for (const Vec3& p : mesh.positions) worst = std::max(worst, distanceToSurface(p, mesh.positions, simplified));
  for (size_t i = 0; i + 2 < simplified.size(); i += 3) {
    const Vec3 a = mesh.positions[simplified[i]], b = mesh.positions[simplified[i + 1]],
               c = mesh.positions[simplified[i + 2]];
    for (const Vec3& p : {(a + b) * 0.5f, (b + c) * 0.5f, (a + c) * 0.5f, (a + b + c) / 3.0f})
      worst = std::max(worst, distanceToSurface(p, mesh.positions, mesh.indices));
  }
  return worst;
}

TEST(ArenaLod, TheStatedErrorBoundsTheBruteForceDistanceBothWays) {
  ArenaOptions options;
  options.lod_ratio = 0.25f;
  for (const scene::Mesh& mesh : {scene::makeSphere(5.0f, 48, 24), hills(48)}) {
    std::vector<uint32_t> simplified;
    const float error = simplifiedMesh(mesh, options, simplified);
    ASSERT_FALSE(simplified.empty());
    EXPECT_LE(simplified.size(), mesh.indices.size() * 3 / 4);  // worth a level
    EXPECT_GT(error, 0.0f);
    const double measured = twoSidedError(mesh, simplified);
    EXPECT_LE(measured, double(error) * 1.0001 + 1e-5) << "stated " << error << ", measured " << measured;
  }
  // A mesh under lod_min_triangles, or no level asked for: none.
  std::vector<uint32_t> none;
  EXPECT_EQ(simplifiedMesh(scene::makeBox(Vec3(0.0f), Vec3(1.0f)), options, none), 0.0f);
  EXPECT_TRUE(none.empty());
  options.lod_ratio = 0.0f;
  EXPECT_EQ(simplifiedMesh(scene::makeSphere(5.0f, 48, 24), options, none), 0.0f);
  EXPECT_TRUE(none.empty());
}

TEST_F(GpuTest, APartDrawnSimplifiedMovesNoVertexByMoreThanTheBound) {
  scene::Scene scene;
  scene.addMaterial(scene::Material{});
  const uint32_t hill_mesh = scene.addMesh(hills(40));
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int i = 0; i < 12; ++i) {
    scene::Object object;
    object.parts.push_back({hill_mesh, 0});
    // Uniform scales, and every third object stretched unevenly and turned (no similarity: the stretch bounds).
    const float s = 0.5f + 1.5f * u(rng);
    const Vec3 scale = i % 3 == 2 ? Vec3(s, 0.6f * s, 1.3f * s) : Vec3(s);
    object.transform = glm::translate(Mat4(1.0f), Vec3(300.0f * u(rng), 300.0f * u(rng), 0.0f)) *
                       glm::rotate(Mat4(1.0f), 6.0f * u(rng), Vec3(0.0f, 0.0f, 1.0f)) * glm::scale(Mat4(1.0f), scale);
    scene.addObject(std::move(object));
  }
  ArenaOptions options;
  options.lod_ratio = 0.25f;
  const SceneArena arena(scene, options);
  const std::vector<uint32_t> indices = arena.readIndices();
  const std::vector<Vec3> positions = arena.readVertexPositions();
  const auto [first, count] = arena.meshClusters(hill_mesh);
  const auto [lod_count, lod_error] = arena.meshLodClusters(hill_mesh);
  ASSERT_GT(lod_count, 0u);
  // The mesh's two levels as triangles over the arena's (reordered) vertices.
  std::vector<uint32_t> full, simple;
  for (uint32_t c = first; c < first + count + lod_count; ++c) {
    const ArenaCluster& cluster = arena.clusters()[c];
    std::vector<uint32_t>& out = c < first + count ? full : simple;
    for (uint32_t i = 0; i < cluster.index_count; ++i)
      out.push_back(cluster.base_vertex + indices[cluster.first_index + i]);
  }
  // Per object, each full vertex's distance to the simplified surface in the world, once.
  std::vector<std::vector<double>> deviation(scene.objects.size());
  for (size_t o = 0; o < scene.objects.size(); ++o) {
    std::vector<Vec3> world(positions.size());
    for (size_t v = 0; v < positions.size(); ++v)
      world[v] = Vec3(scene.objects[o].transform * Vec4(positions[v], 1.0f));
    for (uint32_t v : full) deviation[o].push_back(distanceToSurface(world[v], world, simple));
  }
  const double pixels_per_unit = 360.0 / (2.0 * std::tan(0.5 * degToRad(60.0)));
  size_t simplified_parts = 0, full_parts = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const Vec3 eye(400.0f * u(rng) - 50.0f, 400.0f * u(rng) - 50.0f, 2.0f + 60.0f * u(rng));
    for (const double bound_px : {0.5, 1.0, 2.0}) {
      for (const ArenaPart& part : arena.parts()) {
        const Mat4& model = scene.objects[part.object].transform;
        const double px = partLodErrorPx(part, model, eye, pixels_per_unit);
        if (!(px <= bound_px)) {
          ++full_parts;
          continue;
        }
        ++simplified_parts;
        // Every full vertex: its distance to the simplified surface, in the world, projected at its own distance.
        double worst = 0.0;
        for (size_t k = 0; k < full.size(); ++k) {
          const Vec3 world = Vec3(model * Vec4(positions[full[k]], 1.0f));
          worst = std::max(worst, deviation[part.object][k] * pixels_per_unit / double(glm::length(world - eye)));
        }
        EXPECT_LE(worst, bound_px * 1.0001) << "trial " << trial;
      }
    }
  }
  EXPECT_GT(simplified_parts, 20u);  // the test saw both kinds
  EXPECT_GT(full_parts, 20u);
  EXPECT_GT(lod_error, 0.0f);
}

}  // namespace
}  // namespace farfield::gpu
