// The inner tiles' impostor of the 3D Tiles export (export_tiles.h): a textured heightfield mesh of a capture taken
// from straight above, one vertex per data texel at the point the texel sees (the capture's unprojection of its
// centre at its depth, texture coordinates at the texel's centre), two triangles per 2 x 2 block of data texels
// (one when three are data), split along the diagonal whose ends differ less in height. A depth step between two
// texels becomes a wall one texel wide, and a gap one texel wide keeps its bottom (a mesh on texel corners would
// bridge it), so the mesh lies within about a texel of everything the capture saw. simplifyMesh then collapses it
// with meshoptimizer under a metric error; the tile's error is measured afterwards (export_tiles_deviation.h).
#pragma once

#include "farfield/impostor/capture.h"
#include "farfield/scene/mesh.h"

namespace farfield::store {

// Positions (world), uvs and indices; empty for a capture without data. Throws farfield::Error for a capture whose
// images differ in size from its camera.
scene::Mesh heightfieldMesh(const impostor::ImpostorCapture& capture);

// Collapses edges while meshoptimizer's error estimate stays under error_m metres (topology kept: borders and holes
// stay), then drops the vertices no triangle uses.
void simplifyMesh(scene::Mesh& mesh, double error_m);

}  // namespace farfield::store
