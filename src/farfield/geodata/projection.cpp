// WGS 84 to UTM through PROJ. A PROJ pipeline string is used rather than "EPSG:4326" -> "EPSG:326xx" so that the
// transformation needs neither proj.db nor axis-order normalisation: input is (lon, lat) in degrees, output
// (easting, northing) in metres, exactly the UTM definition of EPSG:326xx/327xx.
#include "farfield/geodata/projection.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>
#include <proj.h>

#include "farfield/core/error.h"

namespace farfield::geodata {

struct LocalProjection::Impl {
  PJ_CONTEXT* ctx = nullptr;
  PJ* pj = nullptr;
  ~Impl() {
    if (pj) proj_destroy(pj);
    if (ctx) proj_context_destroy(ctx);
  }
};

int utmZone(double lon_deg) {
  double lon = std::fmod(lon_deg + 180.0, 360.0);
  if (lon < 0.0) lon += 360.0;
  int zone = int(std::floor(lon / 6.0)) + 1;
  return std::clamp(zone, 1, 60);
}

LocalProjection::LocalProjection(double centre_lon_deg, double centre_lat_deg) : impl_(std::make_unique<Impl>()) {
  if (!std::isfinite(centre_lon_deg) || !std::isfinite(centre_lat_deg) || centre_lon_deg < -180.0 ||
      centre_lon_deg > 180.0 || centre_lat_deg < -84.0 || centre_lat_deg > 84.0)
    throw Error("projection", "centre (" + std::to_string(centre_lon_deg) + ", " + std::to_string(centre_lat_deg) +
                                  ") is not a longitude/latitude inside the UTM range (latitude -84..84)");
  zone_ = utmZone(centre_lon_deg);
  north_ = centre_lat_deg >= 0.0;
  impl_->ctx = proj_context_create();
  if (!impl_->ctx) throw Error("projection", "PROJ: cannot create a context");
  proj_log_level(impl_->ctx, PJ_LOG_NONE);
  const std::string definition = "+proj=pipeline +step +proj=unitconvert +xy_in=deg +xy_out=rad +step +proj=utm +zone=" +
                                 std::to_string(zone_) + (north_ ? "" : " +south") + " +ellps=WGS84";
  impl_->pj = proj_create(impl_->ctx, definition.c_str());
  if (!impl_->pj)
    throw Error("projection", std::string("PROJ cannot create '") + definition +
                                  "': " + proj_context_errno_string(impl_->ctx, proj_context_errno(impl_->ctx)));
  reference_.crs = "EPSG:" + std::to_string((north_ ? 32600 : 32700) + zone_);
  reference_.description = "WGS 84 / UTM zone " + std::to_string(zone_) + (north_ ? "N" : "S");
  const DVec2 c = toProjected(centre_lon_deg, centre_lat_deg);
  if (!std::isfinite(c.x) || !std::isfinite(c.y)) throw Error("projection", "PROJ failed on the centre");
  reference_.origin = DVec3(std::round(c.x), std::round(c.y), 0.0);
}

LocalProjection::~LocalProjection() = default;

DVec2 LocalProjection::toProjected(double lon_deg, double lat_deg) const {
  PJ_COORD in = proj_coord(lon_deg, lat_deg, 0.0, 0.0);
  PJ_COORD out = proj_trans(impl_->pj, PJ_FWD, in);
  if (out.xy.x == HUGE_VAL || out.xy.y == HUGE_VAL) return DVec2(std::nan(""), std::nan(""));
  return DVec2(out.xy.x, out.xy.y);
}

DVec2 LocalProjection::toLocal(double lon_deg, double lat_deg) const {
  return toProjected(lon_deg, lat_deg) - DVec2(reference_.origin.x, reference_.origin.y);
}

std::string geoReferencePathFor(const std::string& glb_path) {
  std::filesystem::path p(glb_path);
  p.replace_extension(".georef.json");
  return p.string();
}

void saveGeoReference(const GeoReference& reference, const std::string& path) {
  nlohmann::json j;
  j["format"] = "farfield-georef";
  j["version"] = 1;
  j["crs"] = reference.crs;
  j["description"] = reference.description;
  j["origin"] = {reference.origin.x, reference.origin.y, reference.origin.z};
  j["note"] = "scene coordinates are metres relative to origin: crs = scene + origin (Z up)";
  std::ofstream out(path);
  if (!out) throw Error(path, "cannot open for writing");
  out << j.dump(2) << "\n";
  if (!out) throw Error(path, "write failed");
}

}  // namespace farfield::geodata
