// Keyframe visibility of low-resolution triangles, Chen et al. 1999 section 3.3 (equation 3).
//
// A vertex is visible in a keyframe when it projects inside the keyframe's image and |z_vertex - z_buffer| <
// thickness, where z_vertex is the vertex's depth from the keyframe camera and z_buffer the keyframe's depth at the
// closest pixel (no interpolation, as the paper says: neighbours may belong to other surfaces). Depths are compared
// as linear distances along the view axis (metres), and the thickness of the visible surface grows with distance:
// thickness = thickness_m + thickness_rel * z_vertex (window depth is reversed-Z and non-linear, so a fixed
// window-depth tolerance would mean centimetres near the camera and kilometres far away). Background pixels (no
// surface) never match. A triangle is visible when all three of its vertices are (a partly occluded triangle with
// visible vertices passes, as in the paper).
//
// The closest pixel's depth belongs to a point up to half a pixel away from the vertex's projection; on a surface
// seen at a grazing angle alpha that point's depth differs by about z * beta * cot(alpha) per pixel (beta = the
// keyframe's view angle of a pixel). So the thickness also has a term for that, from the terrain normal at the
// vertex: thickness = thickness_m + z_vertex * (thickness_rel + footprint_pixels * beta * min(cot(alpha), 20)).
// Without it, distant flat ground seen at a grazing angle fails the test at low image resolutions.
#pragma once

#include <cstdint>
#include <span>
#include <unordered_map>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/image/image.h"
#include "farfield/terrain/quadtree_lod.h"

namespace farfield::terrain {

struct VisibilityOptions {
  float thickness_rel = 0.01f;     // share of the vertex's depth
  float thickness_m = 1.0f;        // metres
  float footprint_pixels = 1.0f;   // pixels of surface footprint allowed for (0 = the paper's plain thickness)
};

// Equation 3 for one world point with surface normal n against a keyframe camera and its depth image (window
// depth, reversed Z, row 0 at the top, the camera's size).
bool vertexVisible(const Camera& keyframe, const image::DepthImage& depth, const Vec3& p, const Vec3& n,
                   const VisibilityOptions& options = {});

// Per-vertex visibility against one keyframe, computed once per grid vertex on first use (the LOD mesh changes
// from frame to frame, so vertices that were not in the keyframe-time mesh are classified when they first appear,
// by the same test against the stored z-buffer; the paper classifies the keyframe-time mesh in one pass). The
// classified vertices are kept in a hash map, so memory and reset follow the vertices the meshes touch (thousands),
// not the grid: per-grid arrays cost 5 bytes a grid point (335 MB on an 8,193^2 grid) and their first allocation,
// inside the first keyframe's frame, took 1 s on a 4,097^2 fractal and 4.5-6 s on the 8,193^2 one.
class KeyframeVisibility {
 public:
  KeyframeVisibility() = default;
  // Starts a new keyframe; `depth` must have the camera's size. Keeps references to lod and depth, which must
  // outlive their use here. region: a keyframe that drew only part of the terrain (a tile's sprite,
  // tile_sprite_renderer.h); vertices outside it are never visible, so a triangle textured with it lies inside it.
  void reset(const QuadtreeLod& lod, const Camera& keyframe, const image::DepthImage* depth,
             const VisibilityOptions& options, const GridRect* region = nullptr);
  bool vertexVisible(uint32_t v);
  bool triangleVisible(uint32_t a, uint32_t b, uint32_t c) { return vertexVisible(a) && vertexVisible(b) && vertexVisible(c); }
  // Reorders a triangle list so that the visible triangles come first; returns how many are visible.
  size_t partition(std::vector<uint32_t>& indices);
  // Share of the triangles of a list that would be visible (does not reorder).
  double visibleShare(std::span<const uint32_t> indices);
  size_t classified() const { return classified_; }

 private:
  const QuadtreeLod* lod_ = nullptr;
  const image::DepthImage* depth_ = nullptr;
  Camera camera_;
  VisibilityOptions options_;
  bool has_region_ = false;
  GridRect region_;
  std::unordered_map<uint32_t, bool> visible_;  // grid vertex -> visible, for the vertices classified so far
  size_t classified_ = 0;
  std::vector<uint32_t> scratch_;
};

}  // namespace farfield::terrain
