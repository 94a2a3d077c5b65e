// How far a simplified mesh moves its texture: texture deviation (Cohen, Olano and Manocha 1998,
// "Appearance-preserving simplification"). A point of a level's triangle shows the texel of its interpolated uv; the
// full mesh shows that texel where its own triangles hold that uv. The distance between the two places bounds how far
// the level moves what the figure looks like on screen, inside its outline as well as on it: a collapse in a flat,
// textured region (a face, a belt) changes no outline and no distance to the mesh, yet slides the texture by an edge.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "farfield/core/math.h"

namespace farfield::scene {

// The barycentric coordinates of p in the 2D triangle (a, b, c); NaN for a triangle of no area.
Vec3 barycentric2(const Vec2& p, const Vec2& a, const Vec2& b, const Vec2& c);

// The barycentric coordinates of the triangle's point nearest p (p's own where the triangle holds it).
Vec3 nearestBarycentric2(const Vec2& p, const Vec2& a, const Vec2& b, const Vec2& c);

// A mesh's triangles in uv space, on a uniform grid, for finding which triangles show a texel.
class UvLocator {
 public:
  struct Hit {
    uint32_t triangle;  // index of the triangle in the mesh's index list / 3
    Vec3 barycentric;
  };
  // indices: three per triangle; uvs: one per vertex. Triangles of no uv area hold no texel.
  UvLocator(std::span<const uint32_t> indices, std::span<const Vec2> uvs);

  // The triangles whose uv triangle holds uv (with a tolerance for points on shared edges); where none does (a
  // texel outside every chart), the one triangle nearest in uv, at its nearest point. Empty only for a mesh with no
  // triangle of uv area.
  void locate(const Vec2& uv, std::vector<Hit>& out) const;

 private:
  size_t cell(int x, int y) const { return size_t(y) * size_t(n_) + size_t(x); }
  void nearest(const Vec2& uv, std::vector<Hit>& out) const;

  std::span<const uint32_t> indices_;
  std::span<const Vec2> uvs_;
  std::vector<uint32_t> usable_;  // triangles of uv area
  Vec2 lo_{0.0f}, size_{1.0f};
  int n_ = 1;
  std::vector<uint32_t> first_, items_;  // per cell: its triangles, items_[first_[c] .. first_[c + 1])
};

// The largest texture deviation, over the poses, of the level's triangles against the full mesh's (both index lists
// over the same vertices and uvs): each level triangle sampled at the points of barycentric coordinates (i, j, k) / n,
// i + j + k = n (its corners are the mesh's own vertices and deviate by nothing), each sample's texel found on the
// full mesh (UvLocator; the nearest of the places that show it) and the distance between the two taken in every pose.
double textureDeviation(std::span<const uint32_t> full, std::span<const uint32_t> level,
                        std::span<const std::vector<Vec3>> poses, std::span<const Vec2> uvs, int n = 4);

}  // namespace farfield::scene
