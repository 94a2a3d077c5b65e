// The geometric deviation of a 3D Tiles inner tile (export_tiles.h): how far, in metres, a textured depth mesh built
// from a capture taken from straight above lies from the surface that capture saw.
//
// The capture's 2.5D surface is, per data pixel, its visible point P = (x, y, h) (the camera's unprojection of the
// pixel centre at its depth) and the vertical wall from h down to the lowest of its 4-neighbours' heights (a depth
// step), sampled every s metres, s the capture's largest texel size (on its farthest data point). The deviation is
// the larger of the two one-sided distances, each taken as a maximum over samples:
//   - surface -> mesh: each surface sample's exact distance to the mesh's nearest triangle;
//   - mesh -> surface: points on every mesh triangle (a barycentric grid of spacing at most s) to the nearest
//     surface sample;
// plus s / sqrt(2) for what lies between samples (any point of either set is within that of a sample). What the
// capture did not see (under overhangs, behind ledges) is not part of the surface measured.
#pragma once

#include "farfield/impostor/capture.h"
#include "farfield/scene/mesh.h"

namespace farfield::store {

struct Deviation {
  double metres = 0.0;             // the deviation above (both directions, slack included)
  double surface_to_mesh = 0.0;    // the one-sided maxima, without the slack
  double mesh_to_surface = 0.0;
  double texel = 0.0;              // s
  Vec3 worst_surface{0.0f};        // the surface sample farthest from the mesh
  Vec3 worst_mesh{0.0f};           // the mesh point farthest from the surface
  size_t surface_samples = 0, mesh_samples = 0;
};

// `mesh` in world space (impostor::DepthMeshImpostor::mesh, built from `capture`); the capture looks down (its
// view direction's z below -0.9). Throws farfield::Error for a capture that does not look down, has no data pixel,
// or a mesh without triangles.
Deviation measureDeviation(const scene::Mesh& mesh, const impostor::ImpostorCapture& capture);

}  // namespace farfield::store
