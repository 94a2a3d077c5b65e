// Triangulation of polygons with holes: building roofs (2D footprints) and CityJSON faces (planar polygons in 3D),
// by a constrained Delaunay triangulation (CGAL) restricted to the inside of the rings.
#pragma once

#include <cstdint>
#include <vector>

#include "farfield/core/math.h"

namespace farfield::geodata {

// Vertices are numbered through the rings in order (ring 0's vertices, then ring 1's, ...), then the extra vertices
// the triangulation had to add where rings cross each other (a malformed input, still covered). Triangles are
// index triples into that numbering.
struct PolygonTriangulation {
  std::vector<uint32_t> indices;
  std::vector<DVec3> extra;  // 3D version: positions of the added vertices (2D version: z = 0)
};

// rings[0] is the outer ring, the others holes (either orientation, no repeated closing vertex). Inside is decided
// by the even-odd rule over all rings, so a hole outside the outer ring adds an island. Triangles are
// counter-clockwise (seen from +z). Rings with fewer than 3 distinct points are ignored. Returns false (and no
// triangles) when nothing of positive area remains or a coordinate is not finite.
bool triangulatePolygon2(const std::vector<std::vector<DVec2>>& rings, PolygonTriangulation& out);

// The same for a planar (or nearly planar) face in 3D: the rings are projected onto the plane of the outer ring
// (Newell's normal) and the triangles are oriented like the outer ring (counter-clockwise around `normal`). Added
// vertices are lifted back into that plane. Returns false for a face without area (collinear points) or with a
// non-finite coordinate. `normal` receives the unit normal.
bool triangulateFace3(const std::vector<std::vector<DVec3>>& rings, PolygonTriangulation& out, DVec3* normal = nullptr);

// Newell's normal of a ring (not normalised; its length is twice the area of the ring's projection).
DVec3 newellNormal(const std::vector<DVec3>& ring);

}  // namespace farfield::geodata
