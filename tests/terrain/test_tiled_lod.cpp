// Tiled quadtree LOD against the whole grid's LOD: the same triangles and quadrants for every camera and threshold
// (without culling exactly; with culling, differences only outside the frustum: the tiles' boxes and coarse tiles'
// spheres cull differently there), while far tiles are read at coarser steps; and on the GPU the tiled mesh's frame
// equals the whole grid's, pixel for pixel.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <set>
#include <tuple>
#include <vector>

#include "farfield/gpu/context.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/terrain_renderer.h"
#include "farfield/terrain/lod_sprite.h"
#include "farfield/terrain/quadtree_lod.h"
#include "farfield/terrain/terrain_texture.h"
#include "farfield/terrain/tile_pager.h"
#include "farfield/terrain/tiled_lod.h"
#include "terrain/tiled_test_terrain.h"

namespace farfield::terrain {
namespace {

using Tri = std::array<uint32_t, 3>;

// Triangles as sets of rotation-normalised index triples (the order of triangles and the starting vertex differ).
std::multiset<Tri> triangles(const LodMesh& mesh) {
  std::multiset<Tri> out;
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    Tri tri{mesh.indices[t], mesh.indices[t + 1], mesh.indices[t + 2]};
    std::rotate(tri.begin(), std::min_element(tri.begin(), tri.end()), tri.end());
    out.insert(tri);
  }
  return out;
}

auto quadrantKey(const LodQuadrant& q) {
  return std::make_tuple(q.centre, q.corners, q.corner_count, q.square);
}

bool outsideOnePlane(const Frustum& f, const QuadtreeLod& lod, const Tri& tri) {
  for (const Vec4& p : f.planes) {
    bool all = true;
    for (uint32_t v : tri) all = all && glm::dot(Vec3(p), lod.position(v)) + p.w < 0.0f;
    if (all) return true;
  }
  return false;
}

TEST(TiledLod, SameMeshAndQuadrantsAsTheWholeGrid) {
  const Heightfield hf = test::tiledTestFractal();
  const QuadtreeLod whole(hf, 16);
  const TileCache cache(test::writeTestCache(hf, "tiled_lod_same"));
  size_t coarse_tiles = 0, fine_tiles = 0, compared = 0;
  for (const Camera& camera : test::tiledTestCameras(hf))
    for (float tau : {0.5f, 1.0f, 4.0f}) {
      TilePager pager(cache, size_t(1) << 30);  // fresh: a tile held finer would serve a coarser request
      LodSettings settings;
      settings.pixel_error = tau;
      settings.cull = false;
      settings.collect_quadrants = true;
      const LodMesh expected = whole.build(camera, settings);
      LodMesh tiled;
      TiledLodFrame frame;
      buildTiledLod(pager, camera, settings, tiled, &frame);
      EXPECT_EQ(frame.tiles_in_view, 16u);
      coarse_tiles += frame.tiles_in_view - frame.full_resolution_tiles;
      fine_tiles += frame.full_resolution_tiles;
      ASSERT_EQ(triangles(tiled), triangles(expected)) << "tau " << tau;
      ASSERT_EQ(tiled.quadrants.size(), expected.quadrants.size());
      for (size_t q = 0; q < tiled.quadrants.size(); ++q)
        ASSERT_EQ(quadrantKey(tiled.quadrants[q]), quadrantKey(expected.quadrants[q])) << "quadrant " << q;
      compared += expected.triangleCount();
    }
  EXPECT_GT(compared, 10000u);
  // Both paths of the tiles were exercised: full resolution near the eye, coarser steps further away.
  EXPECT_GT(coarse_tiles, 20u);
  EXPECT_GT(fine_tiles, 3u);
}

TEST(TiledLod, WithCullingDifferencesOnlyOutsideTheFrustum) {
  const Heightfield hf = test::tiledTestFractal(9);
  const QuadtreeLod whole(hf, 16);
  const TileCache cache(test::writeTestCache(hf, "tiled_lod_cull"));
  TilePager pager(cache, size_t(1) << 30);
  size_t culled_tiles = 0;
  const std::vector<Camera> cameras = test::tiledTestCameras(hf);
  for (const Camera& camera : cameras) {
    LodSettings settings;
    settings.collect_quadrants = true;
    const std::multiset<Tri> expected = triangles(whole.build(camera, settings));
    LodMesh mesh;
    TiledLodFrame frame;
    buildTiledLod(pager, camera, settings, mesh, &frame);
    culled_tiles += frame.tiles_culled;
    const std::multiset<Tri> tiled = triangles(mesh);
    std::vector<Tri> differ;
    std::set_symmetric_difference(tiled.begin(), tiled.end(), expected.begin(), expected.end(),
                                  std::back_inserter(differ));
    const Frustum frustum = Frustum::fromMatrix(camera.viewProjection());
    for (const Tri& t : differ)
      ASSERT_TRUE(outsideOnePlane(frustum, whole, t))
          << "camera " << (&camera - &cameras[0]) << (tiled.count(t) ? " extra" : " missing") << " triangle at "
          << t[0] % 257 << "," << t[0] / 257 << " " << t[1] % 257 << "," << t[1] / 257 << " " << t[2] % 257 << ","
          << t[2] / 257;
    EXPECT_LE(differ.size(), expected.size() / 10 + 10);
  }
  EXPECT_GT(culled_tiles, 0u);
}

TEST(TiledLodGL, FramesEqualTheWholeGridsFrames) {
  gpu::sharedHeadlessContext().makeCurrent();
  const Heightfield hf = test::tiledTestFractal(13);
  const QuadtreeLod whole(hf, 16);
  const image::ColorImage texture = terrainTexture(hf);
  Vec2 scale, offset;
  texCoordTransform(hf, scale, offset);
  gpu::TerrainRenderer renderer(whole.positions(), texture, scale, offset);
  const TileCache cache(test::writeTestCache(hf, "tiled_lod_gl"));
  TilePager pager(cache, cache.residentBytes(1, 1, 1) * 3);  // paging while rendering
  const Vec4 sky(0.62f, 0.74f, 0.88f, 1.0f);
  size_t coarse = 0;
  for (const Camera& camera : test::tiledTestCameras(hf)) {
    LodSettings settings;
    gpu::RenderTarget a(camera.width, camera.height), b(camera.width, camera.height);
    a.clear(sky);
    LodMesh mesh;
    renderLodFrame(whole, renderer, camera, settings, a, mesh);
    const image::ColorImage expected = a.readColor();
    TiledLodFrame frame;
    buildTiledLod(pager, camera, settings, mesh, &frame);
    coarse += frame.tiles_in_view - frame.full_resolution_tiles;
    b.clear(sky);
    renderer.setIndices(mesh.indices, 0);
    renderer.drawTextured(camera, b, 0, mesh.triangleCount(), 0);
    const image::ColorImage tiled = b.readColor();
    size_t sky_pixels = 0;
    for (const auto& p : expected.pixels()) sky_pixels += p == expected.pixels().front() ? 1 : 0;
    EXPECT_LT(sky_pixels, expected.pixels().size());  // the terrain is in view
    EXPECT_EQ(tiled.pixels(), expected.pixels());
  }
  EXPECT_GT(coarse, 0u);
}

}  // namespace
}  // namespace farfield::terrain
