// Single-mesh regular-grid impostor: the baseline the depth mesh of Sillion et al. 1997 is compared with. The
// capture's image plane is cut into a regular grid of squares (two triangles each) with no contour or discrepancy
// constraints, and the grid vertices are reprojected with the depth image.
#pragma once

#include "farfield/core/camera.h"
#include "farfield/image/image.h"
#include "farfield/impostor/capture.h"
#include "farfield/impostor/discrepancy.h"
#include "farfield/impostor/impostor_mesh.h"

namespace farfield::impostor {

struct GridMeshOptions {
  double grid_spacing_px = 16.0;  // size of a grid square (pixels); the last row and column end at the image edge
  // Only for the depth sampler's same-surface test (which neighbours give a vertex its depth gradient).
  DiscrepancyOptions continuity;
};

// Background handling: a triangle is kept when the centre of at least one data pixel lies in it, so the mesh
// covers all data and nothing else of the grid; the texture's alpha cuts the background pixels inside kept
// triangles out. A grid vertex on background takes the depth of the nearest data pixel (no distance limit), which
// pulls the triangles along the silhouette onto the surface next to them instead of stretching them to the far
// plane. A capture without data gives an empty impostor. Throws farfield::Error like buildDepthMesh. Drawn with the
// mesh's interpolated uvs (no projective texturing), its large triangles show the texture warp described in
// depth_mesh.h; the baseline has no refinement for it.
DepthMeshImpostor buildGridMesh(const image::ColorImage& color, const image::DepthImage& depth, const Camera& camera,
                                const GridMeshOptions& options = {}, const image::IdImage* ids = nullptr);
DepthMeshImpostor buildGridMesh(const ImpostorCapture& capture, const GridMeshOptions& options = {});

}  // namespace farfield::impostor
