// Levels of detail of a deforming mesh (a skinned model's mesh in sampled poses) that hold in every pose:
// deformation-sensitive decimation (Mohr and Gleicher 2003, "Deformation sensitive decimation"). Each step merges
// one vertex into a neighbour (a half-edge collapse: kept vertices keep their skin weights, uvs and normals, so a
// level is an index buffer over the model's own vertex buffer), choosing the merge whose quadric error (Garland and
// Heckbert) summed over the poses is least. A simplifier that sees one pose keeps a vertex that is flat there and
// bends away from its neighbours when the joints turn (CesiumMan: a level within 1.5 mm of the bind pose is 3.5 cm
// off in a walk pose); summing the poses' quadrics keeps what any pose needs.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "farfield/core/math.h"

namespace farfield::scene {

struct DeformingLevel {
  std::vector<uint32_t> indices;  // three per triangle, over the mesh's own vertices
  // Per triangle: the mesh's triangle it descends from (a collapse moves a corner, the triangle stays), for
  // per-triangle attributes such as colour regions.
  std::vector<uint32_t> source_triangles;
  // The largest distance between the level's surface and the full mesh's over every pose (deformingDistance).
  double error = 0.0;
  // With uvs: the largest distance by which the level moves a texel over every pose (textureDeviation); 0 without.
  double texture_error = 0.0;
};

struct DeformingLodOptions {
  // Triangles of each level as fractions of the mesh's, decreasing. A level the collapses cannot reach (every
  // remaining merge would fold a triangle or break the surface) is left out.
  std::vector<double> triangle_ratios{0.5, 0.25, 0.125, 0.0625};
  // A merge may not turn any triangle's normal by more than this in any pose (no fold-overs).
  double max_normal_turn_deg = 75.0;
};

// poses[p][v] is vertex v's position in pose p. Vertices at the same position in every pose are one point of the
// surface split for their attributes (uv or normal seams): such a point merges along its seam, each of its vertices
// into the vertex of the same side. triangle_groups (one per triangle, or empty) holds per-triangle attributes such as
// colour regions: the borders between groups, like the surface's own border, are features, held by their quadrics,
// and a point on one moves only along it (where features meet, it stays). With uvs (one per vertex, or empty), a
// point's vertices of one uv are one side of it (normals split for flat shading), so meshes stored a vertex per
// triangle corner merge too. Levels come coarsest last. Throws farfield::Error naming `source` for no pose, poses of
// different sizes, an index count not a multiple of 3, an index out of range, a non-finite position, groups not one
// per triangle or uvs not one per vertex.
std::vector<DeformingLevel> deformingLevels(std::span<const uint32_t> indices,
                                            std::span<const std::vector<Vec3>> poses,
                                            const DeformingLodOptions& options, const std::string& source,
                                            std::span<const uint32_t> triangle_groups = {},
                                            std::span<const Vec2> uvs = {});

// The largest distance, over the poses, from the full mesh's vertices to the level's surface and from the level's
// triangles (their centroids and edge midpoints) to the full mesh's surface (a two-sided, sampled Hausdorff
// distance; a level's vertices are the mesh's own, so they lie on it).
double deformingDistance(std::span<const uint32_t> full, std::span<const uint32_t> level,
                         std::span<const std::vector<Vec3>> poses);

}  // namespace farfield::scene
