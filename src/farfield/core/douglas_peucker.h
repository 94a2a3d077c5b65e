// Douglas-Peucker polyline simplification, shared by the contour and the depth-discrepancy lines of the depth-mesh
// impostor (Sillion et al. 1997, section 4.2; pixels) and the road centre lines of real cities (metres).
#pragma once

#include <vector>

#include "farfield/core/math.h"

namespace farfield {

// Indices of the points kept from an open polyline: the first and the last point always, and every point whose
// removal would move the polyline by more than `tolerance` (distance to the simplified segment that replaces it).
// A polyline of fewer than 3 points is kept whole. tolerance <= 0 keeps every point that is not exactly on the
// segment through its kept neighbours.
std::vector<size_t> douglasPeuckerIndices(const std::vector<DVec2>& points, double tolerance);

// The simplified open polyline (the points at douglasPeuckerIndices).
std::vector<DVec2> simplifyPolyline(const std::vector<DVec2>& points, double tolerance);

// A closed polygon (no repeated closing point) simplified the same way: the loop is cut at its first point and at
// the point farthest from it, and both halves are simplified as open polylines. The result keeps at least 3 points
// when the input has at least 3 and they are not all collinear; every input point lies within `tolerance` of the
// result's boundary.
std::vector<DVec2> simplifyClosed(const std::vector<DVec2>& polygon, double tolerance);

}  // namespace farfield
