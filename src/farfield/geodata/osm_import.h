// A real city from OpenStreetMap: buildings extruded from their footprints (flat roofs, facade textures of the
// procedural city), a planar street graph from the highways whose bounded faces are the blocks, and every building
// assigned to the block holding its footprint's centroid. The result has the shape of gen::City, so every command
// that works on a generated city works on it.
//
// Coordinates: WGS 84 is projected to the UTM zone of the data's centre (PROJ) and shifted so that the centre,
// rounded to whole metres, is the origin (GeoReference); x east, y north, z up, metres.
//
// Heights (OSM Simple 3D Buildings): top = `height` (units such as "12 m", "40 ft" understood), else
// (`building:levels` + `roof:levels`) x 3 m, else the default height (10 m, counted in default_height_used);
// the walls start at `min_height`, else `building:min_level` x 3 m, else the ground. A building outline that
// contains `building:part` areas is replaced by its parts (which carry the detailed heights).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "farfield/gen/city.h"
#include "farfield/geodata/osm_reader.h"
#include "farfield/geodata/planarize.h"
#include "farfield/geodata/projection.h"
#include "farfield/scene/scene.h"
#include "farfield/urban/street_graph.h"

namespace farfield::geodata {

struct OsmImportOptions {
  OsmReadOptions read;                                      // highway classes, tunnels, bbox, height rules
  gen::ObjectGrouping objects = gen::ObjectGrouping::Blocks;  // one object per block or per building
  PlanarizeOptions planarize;                               // junction merge tolerance
  float min_footprint_area = 1.0f;  // m^2: smaller footprints are "zero area" skips
  float outside_tile = 250.0f;      // blocks mode: buildings in no block are grouped in square tiles of this size (m)
  bool ground = true;               // object 1: a ground plane under the data and the streets as asphalt ribbons
};

struct OsmImportStats {
  size_t buildings = 0;            // building outlines imported (including those drawn through their parts)
  size_t parts = 0;                // building:part areas imported
  size_t outlines_replaced = 0;    // outlines not drawn because parts stand in them
  size_t default_height_used = 0;  // buildings or parts with neither height nor levels
  size_t bad_height_tags = 0;      // unreadable height/level tags (the next rule was used)
  size_t outside_blocks = 0;       // buildings whose centroid lies in no block
  size_t outside_bbox = 0;
  SkipCounts skipped;              // buildings skipped per reason (reading and geometry)
  size_t dropped_rings = 0;        // degenerate rings dropped from buildings that kept others
  size_t highway_ways = 0;
  PlanarizeStats streets;
  size_t nodes = 0, ways = 0, relations = 0;
  std::string read_error;          // the file ended early: what was read before it is imported
  double read_s = 0.0, build_s = 0.0, streets_s = 0.0, assign_s = 0.0;  // timings, seconds

  size_t skippedTotal() const;
};

struct OsmCity {
  gen::City city;             // scene (object 1 = ground when OsmImportOptions::ground), streets, object_block
  GeoReference reference;     // scene coordinates + reference.origin = UTM coordinates
  OsmImportStats stats;
};

// Throws farfield::Error naming the file when it cannot be read or holds no usable building or highway (see
// readOsm); malformed buildings are skipped and counted.
OsmCity importOsm(const std::string& path, const OsmImportOptions& options = {});

// "a,b,c" -> highway values, each checked against knownHighwayClasses(); throws farfield::Error naming `option`.
std::vector<std::string> parseHighwayList(const std::string& option, const std::string& text);

}  // namespace farfield::geodata
