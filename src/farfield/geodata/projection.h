// Geographic coordinates (WGS 84 longitude/latitude, degrees) to local metres: the UTM zone holding a chosen
// centre, shifted so that the centre lands near (0, 0). Scene coordinates are floats; keeping them within a few
// kilometres of the origin keeps their precision at a millimetre or better.
#pragma once

#include <memory>
#include <string>

#include "farfield/core/math.h"

namespace farfield::geodata {

// Where local scene coordinates sit in a real coordinate reference system: world = local + origin.
struct GeoReference {
  std::string crs;          // "EPSG:32632" for UTM zone 32N, "EPSG:7415" for a CityJSON file, ...
  std::string description;  // human readable ("WGS 84 / UTM zone 32N")
  DVec3 origin{0.0};        // metres in `crs` of the local origin (z = 0 for OSM)
};

// Writes {"format": "farfield-georef", "version": 1, "crs": ..., "description": ..., "origin": [x, y, z]} to path.
// Throws farfield::Error naming the file when it cannot be written.
void saveGeoReference(const GeoReference& reference, const std::string& path);
// city.glb -> city.georef.json
std::string geoReferencePathFor(const std::string& glb_path);

// UTM zone (1..60) of a longitude in degrees (the Norway and Svalbard exceptions are ignored: any zone works
// for a local projection, these only change which one is used).
int utmZone(double lon_deg);

class LocalProjection {
 public:
  // The UTM zone of (centre_lon, centre_lat) on WGS 84 (PROJ). The origin is the projected centre rounded to
  // whole metres. Throws farfield::Error when PROJ cannot create the transformation or the centre is not a valid
  // longitude/latitude.
  LocalProjection(double centre_lon_deg, double centre_lat_deg);
  ~LocalProjection();
  LocalProjection(const LocalProjection&) = delete;
  LocalProjection& operator=(const LocalProjection&) = delete;

  // Local metres (x east, y north) of a WGS 84 position; non-finite when PROJ fails on it.
  DVec2 toLocal(double lon_deg, double lat_deg) const;
  // Metres in the UTM zone (easting, northing).
  DVec2 toProjected(double lon_deg, double lat_deg) const;

  const GeoReference& reference() const { return reference_; }
  int zone() const { return zone_; }
  bool north() const { return north_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  GeoReference reference_;
  int zone_ = 0;
  bool north_ = true;
};

}  // namespace farfield::geodata
