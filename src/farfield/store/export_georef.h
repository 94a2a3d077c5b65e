// Where an exported tileset sits on the Earth: the scene's georeference file (SCENE.georef.json, format
// "farfield-georef", written by `farfield import`: scene coordinates + origin = coordinates in its CRS) turned into
// the WGS 84 origin and grid rotation of the tileset's east-north-up root transform (export_tiles.h) through PROJ.
#pragma once

#include <optional>
#include <string>

#include "farfield/store/export_tiles.h"

namespace farfield::store {

// The origin's longitude, latitude and height (the CRS's height taken as ellipsoidal when it has none) and the angle
// from true north to the CRS's grid north at the origin (from a point 100 m grid-north of it). None when `path`
// does not exist. Throws farfield::Error naming the file for a malformed file or a CRS PROJ cannot transform.
std::optional<GeoOrigin> readGeoOrigin(const std::string& path);

}  // namespace farfield::store
