// Constrained Delaunay triangulation of the impostor image plane (Sillion et al. 1997, section 4.2, step 5): the
// contour loops and the discrepancy polylines are constraints, grid points add a minimum sampling density, and
// the triangles inside the contour are kept. The only file of Farfield that includes CGAL.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "farfield/core/math.h"

namespace farfield::impostor {

struct TriangulationInput {
  // Closed polygons (no repeated closing vertex). Their segments are constraints, and they define the inside by
  // the even-odd rule (a point is inside when a ray from it crosses the loops an odd number of times), so holes are
  // simply loops nested in others. Loops may touch or cross each other.
  std::vector<std::vector<DVec2>> loops;
  // Open polylines whose segments are constraints but do not bound the inside (depth discrepancy lines).
  std::vector<std::vector<DVec2>> polylines;
  // Free vertices (regular grid points).
  std::vector<DVec2> points;
};

// Optional refinement: called for each inside triangle (vertices in counter-clockwise order in (x, y)); returns a
// point to insert when the triangle must be split. Rounds of insertions repeat until no triangle asks or
// max_points have been inserted.
struct Refinement {
  std::function<std::optional<DVec2>(const DVec2&, const DVec2&, const DVec2&)> split_point;
  size_t max_points = 0;
  int max_rounds = 16;
};

struct Triangulation {
  std::vector<DVec2> vertices;
  // Every finite face of the triangulation, counter-clockwise in (x, y) (clockwise on screen with y down).
  std::vector<std::array<uint32_t, 3>> triangles;
  std::vector<uint8_t> inside;   // per triangle: 1 when inside the loops (even-odd)
  size_t constrained_edges = 0;  // edges marked constrained (constraints split into triangulation edges)
  size_t input_vertices = 0;     // distinct input points (loop, polyline and free points)
  size_t steiner_vertices = 0;   // vertices the triangulation added where constraints cross
  size_t refinement_vertices = 0;
  size_t insideCount() const;
};

// Triangulates the input; constraints may cross (intersection points computed in doubles, recomputed or snapped to
// an edge's end when rounding puts them outside the triangles beside the crossed edge: CGAL's Exact_predicates_tag)
// and may overlap. Degenerate pieces (zero-length segments) are skipped. Non-finite
// coordinates throw farfield::Error.
Triangulation triangulate(const TriangulationInput& input, const Refinement* refinement = nullptr);

// Even-odd inside test against closed loops (the same rule triangulate() uses).
class LoopClassifier {
 public:
  explicit LoopClassifier(const std::vector<std::vector<DVec2>>& loops);
  bool inside(const DVec2& p) const;

 private:
  struct Segment {
    DVec2 a, b;
  };
  std::vector<std::vector<Segment>> rows_;  // segments by the unit rows of y they span
  int row0_ = 0;
};

}  // namespace farfield::impostor
