// CDLOD (terrain/cdlod.h) against brute force: the drawn surface's vertical error at every grid point, projected at
// its distance, within the bound; no crack along any edge two drawn nodes share; the drawn surface continuous while
// the camera moves (no pop). Each check is also shown to fail where its property is broken on purpose.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/terrain/cdlod.h"
#include "farfield/terrain/cdlod_tiles.h"
#include "farfield/terrain/fractal.h"
#include "farfield/terrain/quadtree_lod.h"
#include "terrain/terrain_gl_scene.h"
#include "terrain/tiled_test_terrain.h"

namespace farfield::terrain {
namespace {

Heightfield fractal(int size, uint64_t seed, double relief = 400.0) {
  FractalOptions o;
  o.size = size;
  o.seed = seed;
  o.cell_size = 20.0;
  o.relief = relief;
  return fractalTerrain(o);
}

Camera cameraAt(Vec3 eye, Vec3 at) { return test::makeCamera(eye, at, 256); }

// The drawn (morphed) triangles of one node, in world coordinates.
std::vector<std::array<Vec3, 3>> nodeTriangles(const CdlodTerrain& t, const CdlodNode& n, const CdlodRanges& r,
                                               const Vec3& eye) {
  const int p = t.patchCells();
  std::vector<Vec3> v(size_t(p + 1) * size_t(p + 1));
  for (int j = 0; j <= p; ++j)
    for (int i = 0; i <= p; ++i) v[size_t(i) + size_t(j) * size_t(p + 1)] = t.vertex(n, i, j, r, eye);
  std::vector<std::array<Vec3, 3>> tris;
  for (int j = 0; j < p; ++j)
    for (int i = 0; i < p; ++i) {
      auto at = [&](int a, int b) { return v[size_t(i + a) + size_t(j + b) * size_t(p + 1)]; };
      tris.push_back({at(0, 0), at(1, 0), at(1, 1)});
      tris.push_back({at(0, 0), at(1, 1), at(0, 1)});
    }
  return tris;
}

// Height of a triangle over (x, y) when the point lies in its xy projection (with a tolerance), else nothing.
std::optional<float> heightIn(const std::array<Vec3, 3>& t, double x, double y, double tol = 1e-6) {
  const double x0 = t[0].x, y0 = t[0].y, x1 = t[1].x, y1 = t[1].y, x2 = t[2].x, y2 = t[2].y;
  const double det = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0);
  if (std::abs(det) < 1e-9) return std::nullopt;  // degenerate (collapsed by morphing or clamping)
  const double b1 = ((x - x0) * (y2 - y0) - (x2 - x0) * (y - y0)) / det;
  const double b2 = ((x1 - x0) * (y - y0) - (x - x0) * (y1 - y0)) / det;
  const double b0 = 1.0 - b1 - b2;
  if (b0 < -tol || b1 < -tol || b2 < -tol) return std::nullopt;
  return float(b0 * t[0].z + b1 * t[1].z + b2 * t[2].z);
}

struct SurfaceCheck {
  double worst_px = 0.0;  // largest projected vertical error over the drawn grid points
  size_t points = 0;
  size_t morphing_vertices = 0;  // 0 < k < 1
  int levels_seen = 0;
};

// Every grid point under every drawn node: the drawn surface's height there against the grid's, projected.
SurfaceCheck checkSurface(const CdlodTerrain& t, const Camera& camera, const CdlodSelection& sel) {
  const Heightfield& hf = t.heightfield();
  const double lambda = QuadtreeLod::pixelsPerRadian(camera);
  SurfaceCheck out;
  int level_mask = 0;
  for (const CdlodNode& n : sel.nodes) {
    level_mask |= 1 << n.level;
    for (int j = 0; j <= t.patchCells(); ++j)
      for (int i = 0; i <= t.patchCells(); ++i) {
        const float k = t.morphFactor(n, i, j, sel.ranges, camera.eye);
        if (k > 0.0f && k < 1.0f && ((i | j) & 1)) ++out.morphing_vertices;
      }
    for (const auto& tri : nodeTriangles(t, n, sel.ranges, camera.eye)) {
      double lo_x = 1e30, lo_y = 1e30, hi_x = -1e30, hi_y = -1e30;
      for (const Vec3& p : tri) {
        lo_x = std::min(lo_x, double(p.x)), hi_x = std::max(hi_x, double(p.x));
        lo_y = std::min(lo_y, double(p.y)), hi_y = std::max(hi_y, double(p.y));
      }
      for (int gj = std::max(0, int(std::ceil(lo_y / hf.cell_y - 1e-6)));
           gj <= std::min(hf.height - 1, int(std::floor(hi_y / hf.cell_y + 1e-6))); ++gj)
        for (int gi = std::max(0, int(std::ceil(lo_x / hf.cell_x - 1e-6)));
             gi <= std::min(hf.width - 1, int(std::floor(hi_x / hf.cell_x + 1e-6))); ++gi) {
          const double x = gi * hf.cell_x, y = gj * hf.cell_y;
          const std::optional<float> h = heightIn(tri, x, y);
          if (!h) continue;
          const double d = glm::length(DVec3(camera.eye) - DVec3(x, y, *h));
          out.worst_px = std::max(out.worst_px, lambda * std::abs(double(*h) - hf.at(gi, gj)) / d);
          ++out.points;
        }
    }
  }
  for (int l = 0; l < 32; ++l) out.levels_seen += (level_mask >> l) & 1;
  return out;
}

TEST(Cdlod, LevelsErrorsAndBoxes) {
  const Heightfield hf = fractal(129, 3);
  const CdlodTerrain t(hf, CdlodOptions{8, 16, 0.3f});
  EXPECT_EQ(t.topLevel(), 4);  // 8 * 16 = 128 cells: one node covers the grid
  EXPECT_EQ(t.nodesX(4), 1);
  EXPECT_EQ(t.nodesX(0), 16);
  EXPECT_EQ(t.levelError(0), 0.0f);
  for (int l = 1; l <= t.topLevel(); ++l) {
    EXPECT_GT(t.levelError(l), 0.0f) << l;
    EXPECT_GE(t.levelError(l), t.levelError(l - 1)) << l;
  }
  // Boxes hold every grid point of their node (brute force over the grid).
  for (int l = 0; l <= t.topLevel(); ++l)
    for (int y = 0; y < t.nodesY(l); ++y)
      for (int x = 0; x < t.nodesX(l); ++x) {
        const Box3 box = t.nodeBox({l, x, y});
        const int cells = 8 << l;
        for (int j = y * cells; j <= std::min((y + 1) * cells, hf.height - 1); ++j)
          for (int i = x * cells; i <= std::min((x + 1) * cells, hf.width - 1); ++i)
            ASSERT_TRUE(box.contains(hf.position(i, j))) << l << " " << x << " " << y;
      }
}

TEST(Cdlod, DrawnSurfaceWithinTheBoundAtEveryGridPoint) {
  const Heightfield hf = fractal(257, 5);
  const CdlodTerrain t(hf, CdlodOptions{8, 16, 0.3f});
  const Vec3 centre(float(hf.extentX() / 2), float(hf.extentY() / 2), 0.0f);
  const std::vector<Camera> cameras = {
      cameraAt(Vec3(200, 300, hf.maxHeight() + 50), centre + Vec3(0, 0, hf.minHeight())),
      cameraAt(Vec3(centre.x, centre.y, hf.maxHeight() + 3000), Vec3(centre.x + 10, centre.y + 400, 0)),
      cameraAt(Vec3(4000, 1000, hf.sample(4000, 1000) + 20), Vec3(500, 4500, 0))};
  size_t morphing = 0;
  int most_levels = 0;
  for (float tau : {1.0f, 4.0f, 16.0f})
    for (const Camera& c : cameras) {
      CdlodSelection sel;
      t.select(c, tau, true, sel);
      ASSERT_FALSE(sel.nodes.empty());
      const SurfaceCheck s = checkSurface(t, c, sel);
      EXPECT_GT(s.points, 1000u);
      EXPECT_LE(s.worst_px, tau * 1.001 + 1e-4) << "tau " << tau << " eye " << c.eye.x << "," << c.eye.y;
      morphing += s.morphing_vertices;
      most_levels = std::max(most_levels, s.levels_seen);
    }
  EXPECT_GT(morphing, 100u);     // the check covered morphing vertices,
  EXPECT_GE(most_levels, 3);     // and several levels in one frame

  // The check fails where the bound is not kept: a selection for 16 px checked against 1 px.
  CdlodSelection coarse;
  t.select(cameras[0], 16.0f, true, coarse);
  EXPECT_GT(checkSurface(t, cameras[0], coarse).worst_px, 1.0);
}

// Along every edge two drawn nodes share: each node's border there, the sequence of its drawn (morphed) border
// vertices in 3D with consecutive repeats (vertices collapsed by morphing) removed. The meshes are joined without a
// crack exactly when the two sequences are the same polyline. (Comparing the heights of the two surfaces at points
// of the edge is not the test: where the morph factor changes from one vertex to the next, a cell next to the border
// holds a sliver standing vertically on it, and the two surfaces meet through it.)
double worstCrack(const CdlodTerrain& t, const Camera& camera, const CdlodSelection& sel, int* max_level_step) {
  const Heightfield& hf = t.heightfield();
  const int p = t.patchCells();
  double worst = 0.0;
  *max_level_step = 0;
  struct Border {
    int fixed;      // the grid line (x for a vertical border, y for a horizontal one)
    int lo, hi;     // grid range along it
  };
  auto cellsOf = [&](const CdlodNode& n) { return p << n.level; };
  // Border vertices of node n on side (0: x = x0, 1: x = x1, 2: y = y0, 3: y = y1) between grid lo and hi.
  auto borderVertices = [&](const CdlodNode& n, int side, int lo, int hi) {
    const int cells = cellsOf(n), s = 1 << n.level;
    std::vector<Vec3> out;
    for (int k = 0; k <= p; ++k) {
      const int along = (side < 2 ? n.y : n.x) * cells + k * s;
      if (along < lo || along > hi) continue;
      const int i = side == 0 ? 0 : side == 1 ? p : k;
      const int j = side == 2 ? 0 : side == 3 ? p : k;
      const Vec3 v = t.vertex(n, i, j, sel.ranges, camera.eye);
      if (out.empty() || glm::length(out.back() - v) > 1e-4f) out.push_back(v);
    }
    return out;
  };
  for (size_t a = 0; a < sel.nodes.size(); ++a)
    for (size_t b = 0; b < sel.nodes.size(); ++b) {
      const CdlodNode& na = sel.nodes[a];
      const CdlodNode& nb = sel.nodes[b];
      const int ca = cellsOf(na), cb = cellsOf(nb);
      // a's right side against b's left side, or a's top against b's bottom (grid clamps do not matter inside).
      for (int axis = 0; axis < 2; ++axis) {
        const int a_hi = (axis == 0 ? na.x + 1 : na.y + 1) * ca, b_lo = (axis == 0 ? nb.x : nb.y) * cb;
        if (a_hi != b_lo) continue;
        const int lo = std::max(axis == 0 ? na.y * ca : na.x * ca, axis == 0 ? nb.y * cb : nb.x * cb);
        const int hi = std::min({axis == 0 ? (na.y + 1) * ca : (na.x + 1) * ca,
                                 axis == 0 ? (nb.y + 1) * cb : (nb.x + 1) * cb,
                                 axis == 0 ? hf.height - 1 : hf.width - 1});
        if (hi <= lo) continue;
        *max_level_step = std::max(*max_level_step, std::abs(na.level - nb.level));
        const std::vector<Vec3> va = borderVertices(na, axis == 0 ? 1 : 3, lo, hi);
        const std::vector<Vec3> vb = borderVertices(nb, axis == 0 ? 0 : 2, lo, hi);
        if (va.size() != vb.size()) {
          // Different vertex sets: the gap is at least the distance of a's extra vertices from b's polyline,
          // measured here as the height difference at each of a's vertices against b's segment below it.
          for (const Vec3& v : va) {
            for (size_t q = 0; q + 1 < vb.size(); ++q) {
              const float a0 = axis == 0 ? vb[q].y : vb[q].x, a1 = axis == 0 ? vb[q + 1].y : vb[q + 1].x;
              const float at = axis == 0 ? v.y : v.x;
              if (at < a0 || at > a1 || a1 <= a0) continue;
              const float z = vb[q].z + (vb[q + 1].z - vb[q].z) * (at - a0) / (a1 - a0);
              worst = std::max(worst, double(std::abs(z - v.z)));
            }
          }
          worst = std::max(worst, 1e-3);  // a T-junction even where the heights happen to agree
          continue;
        }
        for (size_t q = 0; q < va.size(); ++q) worst = std::max(worst, double(glm::length(va[q] - vb[q])));
      }
    }
  return worst;
}

TEST(Cdlod, NoCrackAlongSharedEdgesAndTheGridCoveredOnce) {
  const Heightfield hf = fractal(257, 9);
  const CdlodTerrain t(hf, CdlodOptions{8, 16, 0.3f});
  const Camera camera = cameraAt(Vec3(1500, 1200, hf.maxHeight() + 40), Vec3(3000, 3500, hf.minHeight()));
  for (float tau : {1.0f, 4.0f}) {
    CdlodSelection sel;
    t.select(camera, tau, false, sel);  // no culling: the whole grid
    // Covered once: the nodes' areas (clamped to the grid) add up to the grid's and never overlap.
    int64_t area = 0;
    for (const CdlodNode& n : sel.nodes) {
      const Box3 b = t.nodeBox(n);
      area += int64_t(std::lround((b.hi.x - b.lo.x) / hf.cell_x)) * int64_t(std::lround((b.hi.y - b.lo.y) / hf.cell_y));
    }
    EXPECT_EQ(area, int64_t(hf.width - 1) * int64_t(hf.height - 1));
    int step = 0;
    const double crack = worstCrack(t, camera, sel, &step);
    EXPECT_LT(crack, 1e-4) << "tau " << tau;
    EXPECT_EQ(step, 1) << "neighbours of different levels seen, never more than one apart";
  }
  // A terrain half rough, half nearly flat: neighbouring nodes' ranges differ by orders of magnitude, so levels
  // change along the seam, where only the ranges taken as the largest over a vertex's nodes (and the dilated ends
  // of the selection) keep the borders joined.
  Heightfield mixed = hf;
  for (int j = 0; j < mixed.height; ++j)
    for (int i = 0; i < mixed.width / 2; ++i) mixed.at(i, j) = 200.0f + 0.01f * (mixed.at(i, j) - 200.0f);
  const CdlodTerrain mixed_lod(mixed, CdlodOptions{8, 16, 0.3f});
  EXPECT_LT(mixed_lod.nodeError({1, 0, 0}) * 20.0f, mixed_lod.nodeError({1, mixed_lod.nodesX(1) - 1, 0}));
  for (const Camera& c : {camera, cameraAt(Vec3(2560, 600, hf.maxHeight() + 60), Vec3(2560, 4000, hf.minHeight()))}) {
    CdlodSelection sel;
    mixed_lod.select(c, 1.0f, false, sel);
    int step = 0;
    EXPECT_LT(worstCrack(mixed_lod, c, sel, &step), 1e-4);
    EXPECT_LE(step, 1);
    EXPECT_LE(checkSurface(mixed_lod, c, sel).worst_px, 1.001 + 1e-4);
  }
  // Without morphing, a level's odd vertices on an edge next to a coarser node leave a crack: the check sees it.
  const CdlodTerrain unmorphed(hf, CdlodOptions{8, 16, 0.0f});
  CdlodSelection sel;
  unmorphed.select(camera, 1.0f, false, sel);
  int step = 0;
  EXPECT_GT(worstCrack(unmorphed, camera, sel, &step), 0.05);
}

// The drawn surface's height at fixed points while the eye moves in small steps through level changes.
double largestStepChange(const CdlodTerrain& t, const std::vector<Camera>& path, float tau, size_t* level_changes) {
  const Heightfield& hf = t.heightfield();
  std::vector<std::array<double, 2>> samples;
  for (int j = 1; j < 16; ++j)
    for (int i = 1; i < 16; ++i)
      samples.push_back({(i + 0.37) / 16.0 * hf.extentX(), (j + 0.61) / 16.0 * hf.extentY()});
  std::vector<float> previous;
  std::vector<int> previous_level;
  double worst = 0.0;
  *level_changes = 0;
  for (const Camera& camera : path) {
    CdlodSelection sel;
    t.select(camera, tau, false, sel);
    std::vector<float> now(samples.size(), 0.0f);
    std::vector<int> level(samples.size(), -1);
    for (const CdlodNode& n : sel.nodes) {
      const Box3 b = t.nodeBox(n);
      std::vector<std::array<Vec3, 3>> tris;
      for (size_t s = 0; s < samples.size(); ++s) {
        if (samples[s][0] < b.lo.x || samples[s][0] > b.hi.x || samples[s][1] < b.lo.y || samples[s][1] > b.hi.y)
          continue;
        if (tris.empty()) tris = nodeTriangles(t, n, sel.ranges, camera.eye);
        for (const auto& tri : tris)
          if (auto h = heightIn(tri, samples[s][0], samples[s][1], 1e-5)) {
            now[s] = *h;
            level[s] = n.level;
            break;
          }
      }
    }
    if (!previous.empty())
      for (size_t s = 0; s < samples.size(); ++s) {
        worst = std::max(worst, double(std::abs(now[s] - previous[s])));
        if (level[s] != previous_level[s]) ++*level_changes;
      }
    previous = now;
    previous_level = level;
  }
  return worst;
}

TEST(Cdlod, SurfaceContinuousWhileTheEyeMoves) {
  const Heightfield hf = fractal(257, 13, 800.0);
  std::vector<Camera> path;
  for (int f = 0; f <= 400; ++f) {
    const float x = 300.0f + 8.0f * float(f);  // 8 m a frame over 3.2 km
    path.push_back(cameraAt(Vec3(x, 900.0f, hf.maxHeight() + 30.0f), Vec3(x + 100.0f, 2500.0f, hf.minHeight())));
  }
  const CdlodTerrain morphed(hf, CdlodOptions{8, 16, 0.3f});
  size_t changes = 0;
  const double smooth = largestStepChange(morphed, path, 2.0f, &changes);
  EXPECT_GT(changes, 20u);  // the path crossed many level changes
  const CdlodTerrain unmorphed(hf, CdlodOptions{8, 16, 0.0f});
  size_t changes_unmorphed = 0;
  const double popping = largestStepChange(unmorphed, path, 2.0f, &changes_unmorphed);
  EXPECT_GT(changes_unmorphed, 20u);
  // A level change without morphing moves the surface by the level's error at once; with it, a step of 8 m moves
  // it by a small part of that.
  EXPECT_GT(popping, 4.0 * smooth) << "morphed " << smooth << " m, unmorphed " << popping << " m";
  EXPECT_LT(smooth, 0.25 * morphed.levelError(2));
}

// The node ranges are made once per scale and shared by the selections that use it (a 16,385^2 terrain's table is
// 17 MB and 30 ms to make): two selections at one scale hold one table, equal to what another terrain of the same
// grid makes on its own; another bound or image height makes another table; a table no selection holds is let go.
TEST(Cdlod, SelectionsAtOneScaleShareTheirRanges) {
  const Heightfield hf = fractal(129, 4);
  const CdlodTerrain lod(hf, CdlodOptions{8, 16, 0.2f});
  const Camera camera = cameraAt(Vec3(300.0f, 200.0f, hf.maxHeight() + 200.0f), Vec3(1500.0f, 1800.0f, 0.0f));
  CdlodSelection a, b, other;
  lod.select(camera, 1.0f, true, a);
  lod.select(camera, 1.0f, true, b);
  EXPECT_TRUE(a.ranges_changed);
  EXPECT_TRUE(b.ranges_changed);  // new to this selection, though not made again
  ASSERT_TRUE(a.ranges.table);
  EXPECT_EQ(a.ranges.table.get(), b.ranges.table.get());
  lod.select(camera, 1.0f, true, b);
  EXPECT_FALSE(b.ranges_changed);
  const CdlodTerrain alone(hf, CdlodOptions{8, 16, 0.2f});
  CdlodSelection fresh;
  alone.select(camera, 1.0f, true, fresh);
  ASSERT_EQ(fresh.ranges.size(), a.ranges.size());
  for (size_t k = 0; k < a.ranges.size(); ++k) ASSERT_EQ(fresh.ranges.node(k), a.ranges.node(k)) << "node " << k;
  lod.select(camera, 4.0f, true, other);
  EXPECT_NE(other.ranges.table.get(), a.ranges.table.get());
  EXPECT_NE(other.ranges.node(lod.levelOffset(1)), a.ranges.node(lod.levelOffset(1)));
  const std::weak_ptr<const std::vector<Vec3>> held = a.ranges.table;
  a = CdlodSelection{};
  EXPECT_FALSE(held.expired());  // b still holds it
  b = CdlodSelection{};
  EXPECT_TRUE(held.expired()) << "the terrain keeps no table that no selection holds";
}

// Node data read tile by tile from a tile cache: the nodes inside a tile exactly the whole grid's, the coarser ones
// height ranges exact and errors bounded from above (by at most the largest error inside a tile); a selection made
// with them keeps the bound on the drawn surface, with no crack.
TEST(Cdlod, NodeDataFromATileCache) {
  const Heightfield hf = test::tiledTestFractal();
  const TileCache cache(test::writeTestCache(hf, "cdlod_tiles"));  // blocks of 16, tiles of 64 cells
  const CdlodOptions options{8, 16, 0.3f};
  const CdlodTerrain exact(hf, options);
  const CdlodTerrain tiled = cdlodFromTileCache(cache, options);
  const int lt = cdlodTileLevel(cache.layout(), options);
  ASSERT_EQ(lt, 3);  // 64-cell nodes fill a tile
  ASSERT_EQ(tiled.topLevel(), exact.topLevel());
  ASSERT_GT(tiled.topLevel(), lt);
  EXPECT_FALSE(tiled.hasHeights());
  for (int l = 0; l <= exact.topLevel(); ++l)
    for (int y = 0; y < exact.nodesY(l); ++y)
      for (int x = 0; x < exact.nodesX(l); ++x) {
        const CdlodNode n{l, x, y};
        ASSERT_EQ(tiled.nodeHeights(n), exact.nodeHeights(n)) << l << " " << x << " " << y;
        if (l <= lt) {
          ASSERT_EQ(tiled.nodeError(n), exact.nodeError(n)) << l << " " << x << " " << y;
        } else {
          EXPECT_GE(tiled.nodeError(n), exact.nodeError(n) - 1e-3f) << l << " " << x << " " << y;
          EXPECT_LE(tiled.nodeError(n), exact.nodeError(n) + exact.levelError(lt) + 1e-3f);
        }
      }
  const Camera camera = cameraAt(Vec3(300, 200, hf.maxHeight() + 80), Vec3(4000, 4500, hf.minHeight()));
  for (float tau : {1.0f, 4.0f}) {
    CdlodSelection sel;
    tiled.select(camera, tau, false, sel);
    // The vertices as the whole grid's terrain computes them, with the tiled data's ranges.
    EXPECT_LE(checkSurface(exact, camera, sel).worst_px, tau * 1.001 + 1e-4);
    int step = 0;
    EXPECT_LT(worstCrack(exact, camera, sel, &step), 1e-4);
  }
  EXPECT_THROW(cdlodFromTileCache(cache, CdlodOptions{128, 16, 0.3f}), Error);  // a patch larger than a tile
}

// The node data kept beside the cache: written by the first call, read back by the next (the same data), made again
// when damaged or made for another patch size.
TEST(Cdlod, NodeDataKeptBesideTheCache) {
  const Heightfield hf = test::tiledTestFractal(7);
  const std::string path = test::writeTestCache(hf, "cdlod_kept");
  const TileCache cache(path);
  const CdlodOptions options{8, 16, 0.3f};
  std::filesystem::remove(path + ".cdlod");
  bool reused = true;
  const CdlodTerrain made = cdlodFromTileCacheKept(cache, options, &reused);
  EXPECT_FALSE(reused);
  ASSERT_TRUE(std::filesystem::exists(path + ".cdlod"));
  const CdlodTerrain read = cdlodFromTileCacheKept(cache, options, &reused);
  EXPECT_TRUE(reused);
  for (int l = 0; l <= made.topLevel(); ++l)
    for (int y = 0; y < made.nodesY(l); ++y)
      for (int x = 0; x < made.nodesX(l); ++x) {
        ASSERT_EQ(read.nodeHeights({l, x, y}), made.nodeHeights({l, x, y}));
        ASSERT_EQ(read.nodeError({l, x, y}), made.nodeError({l, x, y}));
      }
  cdlodFromTileCacheKept(cache, CdlodOptions{16, 16, 0.3f}, &reused);  // another patch size: made again
  EXPECT_FALSE(reused);
  cdlodFromTileCacheKept(cache, options, &reused);  // rewritten for 16: made again for 8
  EXPECT_FALSE(reused);
  {  // a flipped byte in the node data: the checksum fails, the data are made again (the same)
    std::fstream f(path + ".cdlod", std::ios::binary | std::ios::in | std::ios::out);
    f.seekp(100);
    char c = 0;
    f.read(&c, 1);
    f.seekp(100);
    c = char(c ^ 0x5a);
    f.write(&c, 1);
  }
  const CdlodTerrain again = cdlodFromTileCacheKept(cache, options, &reused);
  EXPECT_FALSE(reused);
  EXPECT_EQ(again.nodeError({1, 0, 0}), made.nodeError({1, 0, 0}));
  cdlodFromTileCacheKept(cache, options, &reused);
  EXPECT_TRUE(reused);
}

TEST(Cdlod, BadInputIsAnError) {
  const Heightfield hf = fractal(65, 1);
  EXPECT_THROW(CdlodTerrain(hf, CdlodOptions{3, 16, 0.3f}), Error);
  EXPECT_THROW(CdlodTerrain(hf, CdlodOptions{8, 16, -1.0f}), Error);
  EXPECT_THROW(CdlodTerrain(hf, CdlodOptions{8, 99, 0.3f}), Error);
  Heightfield tiny(1, 1);
  EXPECT_THROW(CdlodTerrain{tiny}, Error);
  const CdlodTerrain t(hf);
  CdlodSelection sel;
  EXPECT_THROW(t.select(cameraAt(Vec3(0, 0, 500), Vec3(100, 100, 0)), 0.0f, true, sel), Error);
  // A grid whose cell counts are odd has only level 0: every vertex on the grid.
  const Heightfield odd = hf.crop(0, 0, 64, 64);
  EXPECT_EQ(CdlodTerrain(odd).topLevel(), 0);
}

}  // namespace
}  // namespace farfield::terrain
