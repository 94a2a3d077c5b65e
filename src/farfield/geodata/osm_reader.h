// Reading OpenStreetMap files (PBF, XML, compressed XML) with libosmium: building areas (closed ways and
// multipolygon relations, assembled by osmium's area assembler) and highway polylines, in WGS 84 degrees. What
// cannot be used is counted per reason. Projection, meshes and the street graph come after (osm_import.h).
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "farfield/core/math.h"
#include "farfield/geodata/osm_tags.h"

namespace farfield::geodata {

// A geographic box in degrees.
struct LonLatBox {
  double min_lon = 0.0, min_lat = 0.0, max_lon = 0.0, max_lat = 0.0;
  bool contains(double lon, double lat) const {
    return lon >= min_lon && lon <= max_lon && lat >= min_lat && lat <= max_lat;
  }
};
// "minlon,minlat,maxlon,maxlat" -> box. Throws farfield::Error naming `option` for anything else (four numbers,
// longitudes in -180..180, latitudes in -90..90, min < max).
LonLatBox parseLonLatBox(const std::string& option, const std::string& text);

// One polygon of a building: outer ring then holes, (lon, lat) in degrees, no repeated closing vertex.
using LonLatPolygon = std::vector<std::vector<DVec2>>;

struct OsmBuilding {
  int64_t id = 0;               // OSM id of the way or relation
  bool from_relation = false;
  bool is_part = false;         // building:part (not building)
  std::vector<LonLatPolygon> polygons;  // a multipolygon may have several outer rings
  BuildingHeight height;
  std::string roof_shape;       // roof:shape, empty if untagged
  double roof_height = 0.0;     // roof:height (or roof:levels x level height) in metres, 0 if untagged
};

struct OsmHighway {
  int64_t id = 0;
  std::vector<DVec2> points;  // (lon, lat); a way with missing nodes is cut into several highways
  std::string kind;           // value of the highway tag
  float width = 10.0f;
  int street_class = 1;
};

struct OsmReadOptions {
  std::vector<std::string> highways = defaultHighwaySelection();  // highway values that become streets
  bool include_tunnels = false;   // tunnel=yes ways are underground: not streets of the city's surface
  std::optional<LonLatBox> bbox;  // buildings whose first vertex lies inside, highway segments touching it
  HeightOptions heights;
};

// Skips are counted per reason ("missing nodes", "unclosed ring", ...); the map is ordered for printing.
using SkipCounts = std::map<std::string, size_t>;

struct OsmData {
  std::vector<OsmBuilding> buildings;
  std::vector<OsmHighway> highways;
  SkipCounts skipped;                // buildings (and parts) that could not be read, per reason
  size_t highway_ways = 0;           // highway ways selected
  size_t highway_missing_nodes = 0;  // highway ways with missing nodes (cut at the gaps)
  size_t outside_bbox = 0;           // buildings left out by --bbox
  size_t nodes = 0, ways = 0, relations = 0;  // objects read
  std::string read_error;            // non-empty when the file is truncated or corrupt: what was read before is kept
};

// Throws farfield::Error naming the file when it does not exist, is of an unknown format, or is unreadable before
// any building or highway was read. A file that breaks later (truncated, corrupt block) keeps what was read and
// reports it in read_error.
OsmData readOsm(const std::string& path, const OsmReadOptions& options = {});

}  // namespace farfield::geodata
