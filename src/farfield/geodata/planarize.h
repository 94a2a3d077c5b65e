// Street polylines (OSM highways in local metres) to a planar street graph by iterated snap rounding: the plane is
// cut into square pixels of side `merge_tolerance`; every pixel holding a street end or a crossing is "hot", and
// every street is routed through the centres of the hot pixels it touches, in order. Points in one pixel become
// one junction, streets are split where they cross, and a street passing within about half a pixel of a junction is
// routed through it. The result satisfies every check of urban::StreetGraph::build (no crossings, overlaps or
// duplicates), so its bounded faces are the city blocks. Junctions move by at most half a pixel diagonal per round.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "farfield/core/math.h"
#include "farfield/urban/street_graph.h"

namespace farfield::geodata {

struct StreetPolyline {
  std::vector<DVec2> points;  // local metres, in order along the street
  float width = 10.0f;        // metres
  int street_class = urban::kStreet;
};

struct PlanarizeOptions {
  // Pixel side, metres (must be positive): points in one pixel merge into a junction at its centre.
  double merge_tolerance = 0.5;
  int max_rounds = 32;  // snap-rounding rounds before any street still in contact with another is dropped
};

struct PlanarizeStats {
  size_t input_points = 0;
  size_t input_segments = 0;      // consecutive point pairs of the polylines
  size_t merged_points = 0;       // distinct input points that fell into a pixel already holding another
  size_t zero_length = 0;         // input segments whose two ends fell into one pixel
  size_t duplicates = 0;          // input segments repeating another (same two points, either direction)
  size_t crossings = 0;           // pixels made hot by a crossing of two streets
  size_t snapped_to_junction = 0; // junctions a street was routed through besides its own ends (last round)
  size_t unresolved = 0;          // segments dropped because they still met another after max_rounds
  size_t rounds = 0;
};

// Throws farfield::Error naming `source` for a non-positive tolerance or non-finite points. All tests are exact
// (integer grid), and the junctions are floats on which StreetGraph::build's double-precision tests are exact too.
urban::StreetGraph planarizeStreets(const std::vector<StreetPolyline>& polylines, const PlanarizeOptions& options = {},
                                    PlanarizeStats* stats = nullptr, const std::string& source = "streets");

}  // namespace farfield::geodata
