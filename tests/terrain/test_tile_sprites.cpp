// Sprites per terrain tile: the error of every kept tile sprite, measured by brute force (the ray from the tile's
// keyframe eye through each skipped grid point C, cast against the frame's actual low-resolution triangles, seen
// from the current eye), stays under epsilon (with a stated margin: see below); without refreshes it does not (the
// check can fail); far tiles keep their sprites longer than near ones.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

#include "farfield/terrain/flythrough.h"
#include "farfield/terrain/fractal.h"
#include "farfield/terrain/tile_sprites.h"

namespace farfield::terrain {
namespace {

Heightfield spriteFractal() {
  FractalOptions o;
  o.size = 257;
  o.seed = 21;
  o.cell_size = 20.0;
  o.relief = 700.0;
  o.roughness = 0.5;
  return fractalTerrain(o);
}

std::vector<Camera> pathCameras(const Heightfield& hf, int frames) {
  FlythroughOptions fo;
  fo.frames = frames;
  std::vector<Camera> out;
  for (const Viewpoint& v : flythroughPath(hf, fo)) {
    Camera c;
    c.eye = v.eye;
    c.at = v.at;
    c.fov_y = v.fov_y;
    c.width = c.height = 256;
    c.near_plane = 2.0f;
    c.far_plane = 100000.0f;
    out.push_back(c);
  }
  return out;
}

// Where the line through v1 and c crosses the frame's low-resolution triangles within `reach` (horizontally) of c,
// nearest to c (brute force over every triangle): the sprite shows c there. None when the line grazes the surface
// there (the paper's metric then takes a plane; this check skips the quadrant and counts it).
std::optional<DVec3> castOnLowMesh(const QuadtreeLod& lod, const LodMesh& low, DVec3 v1, DVec3 c, double reach) {
  const DVec3 d = c - v1;
  std::optional<DVec3> best;
  double best_dist = reach;
  for (size_t t = 0; t < low.indices.size(); t += 3) {
    const DVec3 a(lod.position(low.indices[t])), b(lod.position(low.indices[t + 1])),
        e(lod.position(low.indices[t + 2]));
    const DVec3 e1 = b - a, e2 = e - a, p = glm::cross(d, e2);
    const double det = glm::dot(e1, p);
    if (std::abs(det) < 1e-12) continue;
    const DVec3 s = v1 - a;
    const double u = glm::dot(s, p) / det;
    const DVec3 q = glm::cross(s, e1);
    const double v = glm::dot(d, q) / det;
    if (u < -1e-9 || v < -1e-9 || u + v > 1.0 + 1e-9) continue;
    const DVec3 hit = v1 + d * (glm::dot(e2, q) / det);
    const double dist = glm::length(DVec2(hit - c));
    if (dist <= best_dist) best_dist = dist, best = hit;
  }
  return best;
}

// Per tile: the brute-force error (pixels) of the tiles whose sprite was kept in this frame.
size_t grazing = 0, cast = 0;

std::map<std::pair<int, int>, double> bruteForceErrors(const QuadtreeLod& lod, const TileSprites& sprites,
                                                       const Camera& camera, size_t frame) {
  std::map<std::pair<int, int>, std::pair<double, size_t>> sums;
  const DVec3 v2(camera.eye);
  for (const LodQuadrant& q : sprites.lowMesh().quadrants) {
    const IVec2 t = sprites.tileOf(q.centre);
    const auto it = sprites.sprites().find({t.x, t.y});
    if (it == sprites.sprites().end() || it->second.since == frame) continue;  // refreshed here: no error
    const DVec3 c(lod.position(q.centre)), v1(it->second.key_eye);
    double reach = 0.0;
    for (int k = 0; k < q.corner_count; ++k)
      reach = std::max(reach, glm::length(DVec2(DVec3(lod.position(q.corners[size_t(k)])) - c)));
    const std::optional<DVec3> c_prime = castOnLowMesh(lod, sprites.lowMesh(), v1, c, reach);
    if (!c_prime) {
      ++grazing;
      continue;
    }
    ++cast;
    const double cosine = glm::dot(glm::normalize(c - v2), glm::normalize(*c_prime - v2));
    const double theta = std::acos(std::clamp(cosine, -1.0, 1.0));
    auto& s = sums[{t.x, t.y}];
    s.first += theta * theta;
    ++s.second;
  }
  std::map<std::pair<int, int>, double> out;
  for (const auto& [tile, s] : sums) out[tile] = std::sqrt(s.first / double(s.second)) / pixelAngle(camera);
  return out;
}

TEST(TileSprites, KeptSpritesStayUnderEpsilonByBruteForce) {
  const Heightfield hf = spriteFractal();
  const QuadtreeLod lod(hf, 16);
  const std::vector<Camera> cameras = pathCameras(hf, 90);
  TileSpriteOptions o;
  o.tile_cells = 64;
  o.epsilon = 1.0;
  TileSprites sprites(lod, o);
  double worst = 0.0;
  size_t kept = 0, refreshed = 0, over = 0;
  std::map<std::pair<int, int>, size_t> refreshes;
  for (size_t f = 0; f < cameras.size(); ++f) {
    const TileSpriteFrame frame = sprites.advance(cameras[f]);
    refreshed += frame.tiles_refreshed;
    EXPECT_LT(frame.max_tile_error_px, o.epsilon);
    for (const auto& [tile, px] : bruteForceErrors(lod, sprites, cameras[f], f)) {
      worst = std::max(worst, px);
      over += px >= o.epsilon ? 1 : 0;
      ++kept;
    }
  }
  EXPECT_GT(kept, 200u);
  EXPECT_GT(refreshed, 16u);
  // Equation 2 estimates the low surface at C from the quadrant's corners (C^); the mesh's own diagonal lies a
  // little elsewhere, so the brute-force error may pass epsilon by a margin on a few tile-frames (measured: at most
  // 1.35 px at 1 px on this path, 28 of 449 tile-frames at or over 1 px).
  EXPECT_LT(worst, 1.5 * o.epsilon) << "kept tile sprites " << kept;
  EXPECT_LT(double(over), 0.1 * double(kept));
  EXPECT_LT(double(grazing), 0.2 * double(cast));
  std::printf("brute-force error of kept tile sprites: worst %.3f px, %zu of %zu tile-frames at or over epsilon "
              "(%zu quadrants cast, %zu grazing)\n", worst, over, kept, cast, grazing);
}

TEST(TileSprites, WithoutRefreshesTheBruteForceErrorExceedsEpsilon) {
  const Heightfield hf = spriteFractal();
  const QuadtreeLod lod(hf, 16);
  const std::vector<Camera> cameras = pathCameras(hf, 90);
  TileSpriteOptions o;
  o.tile_cells = 64;
  o.epsilon = 1e9;  // never refreshed after the first keyframe
  TileSprites sprites(lod, o);
  double worst = 0.0;
  for (size_t f = 0; f < cameras.size(); f += 1) {
    sprites.advance(cameras[f]);
    for (const auto& [tile, px] : bruteForceErrors(lod, sprites, cameras[f], f)) worst = std::max(worst, px);
  }
  EXPECT_GT(worst, 1.0);
}

TEST(TileSprites, FarTilesKeepTheirSpritesLonger) {
  const Heightfield hf = spriteFractal();
  const QuadtreeLod lod(hf, 16);
  const std::vector<Camera> cameras = pathCameras(hf, 120);
  TileSpriteOptions o;
  o.tile_cells = 32;
  TileSprites sprites(lod, o);
  // Per refresh: the eye's distance to the tile's centre, and how long the tile's previous sprite had lasted.
  std::vector<std::pair<double, double>> lifetimes;
  std::map<std::pair<int, int>, size_t> since;
  size_t whole = 0;
  for (size_t f = 0; f < cameras.size(); ++f) {
    whole += sprites.advance(cameras[f]).whole_keyframe ? 1 : 0;
    for (const auto& [tile, state] : sprites.sprites()) {
      if (state.since != f) continue;
      auto it = since.find(tile);
      if (it != since.end()) {
        const Vec3 centre(float((tile.first + 0.5) * 32 * hf.cell_x), float((tile.second + 0.5) * 32 * hf.cell_y),
                          hf.sample((tile.first + 0.5) * 32 * hf.cell_x, (tile.second + 0.5) * 32 * hf.cell_y));
        lifetimes.push_back({glm::length(cameras[f].eye - centre), double(f - it->second)});
      }
      since[tile] = f;
    }
  }
  ASSERT_GT(lifetimes.size(), 20u);
  // Measured: far half 7.4 frames, near half 5.6.
  std::sort(lifetimes.begin(), lifetimes.end());
  const size_t half = lifetimes.size() / 2;
  double near = 0.0, far = 0.0;
  for (size_t i = 0; i < half; ++i) near += lifetimes[i].second / double(half);
  for (size_t i = half; i < lifetimes.size(); ++i) far += lifetimes[i].second / double(lifetimes.size() - half);
  EXPECT_GT(far, 1.15 * near) << "near " << near << " far " << far << " whole-frame keyframes " << whole;
  std::printf("mean sprite lifetime: near tiles %.1f frames, far tiles %.1f; whole-frame keyframes %zu of %zu\n",
              near, far, whole, cameras.size());
}

}  // namespace
}  // namespace farfield::terrain
