// 3D impostor as a textured depth mesh (Sillion et al. 1997, section 4.2): external contour, depth discrepancy
// lines and grid points, constrained Delaunay triangulation, reprojection of the vertices with the depth image.
#pragma once

#include "farfield/core/camera.h"
#include "farfield/image/image.h"
#include "farfield/impostor/capture.h"
#include "farfield/impostor/contour.h"
#include "farfield/impostor/discrepancy.h"
#include "farfield/impostor/impostor_mesh.h"

namespace farfield::impostor {

struct DepthMeshOptions {
  // Capture (used by creationCamera(); buildDepthMesh takes the image size from its inputs).
  int resolution = 512;                  // width = height, pixels
  float fov_y = float(degToRad(60.0));   // radians
  // Step 3: external contour, Douglas-Peucker tolerance and smallest loop kept (pixels).
  ContourOptions contour{1.0, 4.0};
  // The contour is traced around the data grown by this many pixels (8-neighbour dilation), so that simplifying
  // it never cuts a data pixel off: the texture's alpha cuts the overhang back to the exact silhouette.
  int contour_dilation_px = 1;
  // Step 4: depth discrepancy threshold (relative by default) and chain simplification.
  DiscrepancyOptions discrepancy;
  // Step 5: regular grid points inside the contour every grid_spacing_px pixels (<= 0: none), the paper's minimum
  // sampling density. Points within the contour tolerance + 2 px of the background or 1 px of a discrepancy chain
  // are left out (they would only make slivers against the constraints).
  double grid_spacing_px = 32.0;
  // Texture warp bound (pixels; <= 0: off, the default) for renderers that interpolate the mesh's uvs instead of
  // projecting the texture (see textureProjection() in impostor_mesh.h): a triangle whose vertices lie at different
  // depths then shows its texture shifted by up to about edge_length * |d1 - d2| / (2 (d1 + d2)) pixels from the
  // creation viewpoint. With a bound, triangles that do not span a depth step and exceed it are split at the
  // midpoint of their worst edge.
  double max_texture_warp_px = 0.0;
  size_t max_refinement_points = 20000;
};

// The creation camera of an impostor: at `eye` looking at `at`, Z up, resolution x resolution pixels, fov_y of the
// options, with the given depth range. Throws farfield::Error when unusable (eye == at, view along Z).
Camera creationCamera(const Vec3& eye, const Vec3& at, const DepthMeshOptions& options, float near_plane,
                      float far_plane);

// Builds the impostor from a capture (colour, window depth, creation camera; ids optional). The images must have
// the camera's size. A capture without data gives an empty impostor. Throws farfield::Error for mismatched sizes or
// depth values outside [0, 1]. CPU only and without shared state: safe to run on several threads at once (the
// capture itself needs the thread of the GL context).
DepthMeshImpostor buildDepthMesh(const image::ColorImage& color, const image::DepthImage& depth,
                                 const Camera& camera, const DepthMeshOptions& options = {},
                                 const image::IdImage* ids = nullptr);
// From captureView()'s result, with ids and the render time in the stats.
DepthMeshImpostor buildDepthMesh(const ImpostorCapture& capture, const DepthMeshOptions& options = {});

}  // namespace farfield::impostor
