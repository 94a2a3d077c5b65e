// Centre lines of road surfaces (CityGML and CityJSON transportation objects are areas, not the lines a street
// graph needs): the road polygons are united (CGAL Boolean operations, exact), and the chordal axis of each united
// area gives the lines. The area is triangulated (CGAL's constrained Delaunay triangulation) and its border edges
// are split until none is longer than the road is wide across it; a triangle with one border edge links the midpoints of its two chords, which lie midway
// between the road's borders, and a triangle without border edges is a junction linking the midpoints of its three
// chords through its centre. Junction triangles closer to each other than the road is wide become one junction, and
// dead-end branches shorter than the road is wide (the traces of a border's corner) are dropped. The chains between
// junctions and ends are simplified into polylines that go to planarizeStreets (planarize.h) like OSM highways.
//
// This replaced CGAL's straight skeleton, whose builder in CGAL 5.5 reads freed memory on some road networks (a fuzz
// finding that depended on the heap's layout); the triangulation is robust to touching rings and near-degenerate
// input, and its centre lines are exact where the borders are parallel.
#pragma once

#include <string>
#include <vector>

#include "farfield/core/math.h"
#include "farfield/geodata/planarize.h"

namespace farfield::geodata {

struct RoadCentreLineStats {
  size_t polygons = 0;          // road polygons given
  size_t invalid_polygons = 0;  // not simple (self-intersecting) or without area: left out of the union
  size_t united = 0;            // polygons (with holes) after the union
  size_t cleaned_vertices = 0;  // near-duplicate or near-collinear vertices (under 5 cm) dropped before triangulating
  size_t degenerate_areas = 0;  // united areas with under three vertices left after that, or too large for
                                // doubles (perimeter overflows): no centre lines
  size_t triangles = 0;         // triangles inside the road areas
  size_t junctions = 0;         // junctions after merging the junction triangles
  size_t spurs = 0;             // dead-end branches dropped
};

// `polygons`: each an outer ring then holes, in local metres, either orientation, no repeated closing vertex.
// Returns one polyline per chain between junctions and ends, its width the median width of the road along it (at
// least `min_width`). Never throws for bad polygons (they are counted).
std::vector<StreetPolyline> roadCentreLines(const std::vector<std::vector<std::vector<DVec2>>>& polygons,
                                            RoadCentreLineStats* stats = nullptr, float min_width = 2.0f);

}  // namespace farfield::geodata
