// CityGML 1.0 and 2.0 import through libcitygml: buildings with their parts, installations and boundary surfaces
// (LoD1 solids, LoD2 solids, multi-surfaces and Wall/Roof/GroundSurfaces), transportation, land use, vegetation,
// water, relief and other city objects, as scene objects with the surface classes, appearance materials and
// textures of the CityJSON importer (city_surfaces.h): one scene object per root city object (a building with its
// parts is one object); every polygon triangulated in its plane with its holes (triangulate.h).
//
// LoD: per object the highest LoD present (not above CityGmlImportOptions::max_lod); a polygon reached twice (an
// LoD2 solid that links the polygons of its boundary surfaces) is drawn once. Appearances: the theme asked for, else
// the first theme in the file; a polygon's texture (ParameterizedTexture with texture coordinates per ring) wins
// over its X3DMaterial (diffuseColor, transparency), which wins over its class colour. Texture images are read
// relative to the file; a missing or unreadable one is a counted warning with a checkerboard in its place.
//
// Coordinates: the file's CRS (srsName of the envelope or the geometries) is kept; the centre of the bounding box
// of the imported vertices, rounded to whole metres (z kept at 0), is subtracted, as the CityJSON importer does
// (GeoReference gives the offset back). Files in a geographic CRS (degrees) are refused with an error naming the
// CRS: Farfield's scenes are metres.
//
// Streets: where the file has transportation objects (Road, Railway, Square, Track), their surfaces are also the
// street graph's source: the centre lines of their union (road_centrelines.h) are planarised as the OSM importer's
// highways are (planarize.h), the graph's bounded faces are the blocks, and the buildings are grouped into one
// object per block (or kept one per building) with the same rules as importOsm. Without transportation objects the
// street graph is empty and every building is its own object.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "farfield/gen/city.h"
#include "farfield/geodata/planarize.h"
#include "farfield/geodata/projection.h"
#include "farfield/scene/import.h"

namespace farfield::geodata {

struct CityGmlImportOptions {
  std::optional<unsigned> max_lod;  // per object, the highest LoD not above this (default: the highest present)
  bool ground_objects = true;       // roads, railways, squares, land use, vegetation, water, relief
  bool other_objects = true;        // bridges, tunnels, city furniture, generic objects
  std::string theme;                // appearance theme (empty: the first in the file); unknown: an error
  // Where the file has streets: one object per block (the street graph's faces) or per building.
  gen::ObjectGrouping objects = gen::ObjectGrouping::Blocks;
  PlanarizeOptions planarize;      // junction merge tolerance of the street graph
  float outside_tile = 250.0f;     // blocks mode: buildings in no block are grouped in square tiles of this size (m)
};

struct CityGmlStats {
  std::string version;            // "1.0" or "2.0" (from the CityGML namespace of the file)
  std::string crs;                // srsName as the file gives it
  size_t city_objects = 0;        // root city objects in the file
  size_t buildings = 0;           // Building objects imported (a part without its building counts as one)
  size_t building_parts = 0;      // BuildingPart objects imported (inside their building's object)
  size_t ground_objects = 0;      // roads, land use, ... imported
  size_t other_objects = 0;       // bridges, generic objects, ... imported
  std::map<std::string, size_t> objects_by_type;  // imported root objects per CityGML type
  std::map<unsigned, size_t> lods;  // root objects per LoD used
  size_t surfaces = 0;            // polygons triangulated
  size_t semantic_surfaces = 0;   // of which with a semantic class (boundary surfaces)
  size_t inferred_surfaces = 0;   // building polygons classified by their normal
  size_t holes = 0;               // interior rings
  size_t shared_polygons = 0;     // polygons reached a second time in one object (drawn once)
  size_t textured_surfaces = 0;   // drawn with a texture (placeholders included)
  size_t material_surfaces = 0;   // drawn in an X3DMaterial's colour
  size_t bad_texture_coordinates = 0;  // textured polygons whose coordinates do not fit their rings (untextured)
  std::vector<std::string> themes;     // appearance themes in the file
  std::string theme;                   // used (empty: none)
  scene::ImportStats import;           // missing or unreadable texture files (checkerboard placeholders)
  uint64_t triangles = 0;
  std::map<std::string, size_t> skipped;  // per reason: polygons and objects that could not be used
  // Streets (transportation objects present).
  size_t road_objects = 0;         // transportation objects whose surfaces made the street graph
  size_t road_polygons = 0;
  size_t centre_line_segments = 0;  // segments of the roads' centre lines given to the planariser
  PlanarizeStats streets;
  size_t outside_blocks = 0;       // buildings whose centroid lies in no block
  double read_s = 0.0, build_s = 0.0, streets_s = 0.0;

  size_t skippedTotal() const;
};

struct CityGmlScene {
  // scene: without streets, one object per root city object; with streets, object 1 is the ground (the
  // transportation, land use and other ground surfaces), then the blocks (or buildings), then the other objects.
  // streets: empty without transportation objects. object_block: per object, its block or -1.
  gen::City city;
  GeoReference reference;  // scene + reference.origin = file coordinates (reference.crs = the file's srsName)
  DVec3 file_min{0.0}, file_max{0.0};  // bounds of the imported vertices, in file coordinates
  CityGmlStats stats;
};

// Throws farfield::Error naming the file for: a missing file, XML that does not parse (with the line and column),
// a document without a CityModel, a geographic CRS, an unknown theme, or when no surface could be imported.
// Degenerate polygons and objects without geometry are skipped and counted.
CityGmlScene importCityGml(const std::string& path, const CityGmlImportOptions& options = {});

// The same for a document held in memory (fuzzing, tests): `source` names it in errors, textures are read relative
// to `base_dir`.
CityGmlScene importCityGmlText(const std::string& text, const std::string& source, const std::string& base_dir,
                               const CityGmlImportOptions& options = {});

}  // namespace farfield::geodata
