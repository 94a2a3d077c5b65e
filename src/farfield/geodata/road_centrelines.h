// Centre lines of road surfaces (CityGML and CityJSON transportation objects are areas, not the lines a street
// graph needs): the road polygons are united (CGAL Boolean operations, exact), and the straight skeleton of each
// united polygon (CGAL) gives the lines: its inner bisectors, the edges between two skeleton nodes, run midway
// between the road's borders, and a node's time is its distance to the nearest border, so twice it is the road's
// width there. The skeleton's short dead-end branches (shorter than the road is wide: the traces of a border's
// corner) are dropped. The lines go to planarizeStreets (planarize.h) like OSM highways.
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
  size_t cleaned_vertices = 0;  // near-duplicate or near-collinear vertices (under 5 cm) dropped before the skeleton
  size_t degenerate_areas = 0;  // united areas whose rings still touch or cross after that: left without centre lines
  size_t skeleton_edges = 0;    // inner bisectors of their skeletons
  size_t spurs = 0;             // dead-end branches dropped
};

// `polygons`: each an outer ring then holes, in local metres, either orientation, no repeated closing vertex.
// Returns one two-point polyline per kept skeleton edge, its width twice the mean distance of its ends to the
// border (at least `min_width`). Never throws for bad polygons (they are counted).
std::vector<StreetPolyline> roadCentreLines(const std::vector<std::vector<std::vector<DVec2>>>& polygons,
                                            RoadCentreLineStats* stats = nullptr, float min_width = 2.0f);

}  // namespace farfield::geodata
