// The georeference of an exported tileset through PROJ: the CRS of SCENE.georef.json to WGS 84 (EPSG:4979,
// longitude, latitude, ellipsoidal height; axis order normalised to longitude first).
#include "farfield/store/export_georef.h"

#include <proj.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>

#include <nlohmann/json.hpp>

#include "farfield/core/error.h"

namespace farfield::store {

std::optional<GeoOrigin> readGeoOrigin(const std::string& path) {
  if (!std::filesystem::exists(path)) return std::nullopt;
  nlohmann::json j;
  try {
    std::ifstream in(path);
    in >> j;
  } catch (const std::exception& e) {
    throw Error(path, std::string("not JSON: ") + e.what());
  }
  if (!j.is_object() || j.value("format", "") != "farfield-georef")
    throw Error(path, "not a Farfield georeference (\"format\": \"farfield-georef\")");
  if (!j.contains("crs") || !j["crs"].is_string() || !j.contains("origin") || !j["origin"].is_array() ||
      j["origin"].size() != 3)
    throw Error(path, "needs \"crs\" (a string) and \"origin\" ([x, y, z])");
  double origin[3];
  for (size_t i = 0; i < 3; ++i) {
    if (!j["origin"][i].is_number() || !std::isfinite(j["origin"][i].get<double>()))
      throw Error(path, "origin[" + std::to_string(i) + "] is not a finite number");
    origin[i] = j["origin"][i].get<double>();
  }
  const std::string crs = j["crs"].get<std::string>();

  struct Proj {
    PJ_CONTEXT* ctx = proj_context_create();
    PJ* pj = nullptr;
    ~Proj() {
      if (pj) proj_destroy(pj);
      proj_context_destroy(ctx);
    }
  } proj;
  proj_log_level(proj.ctx, PJ_LOG_NONE);
  PJ* raw = proj_create_crs_to_crs(proj.ctx, crs.c_str(), "EPSG:4979", nullptr);
  if (raw) {
    proj.pj = proj_normalize_for_visualization(proj.ctx, raw);
    proj_destroy(raw);
  }
  if (!proj.pj)
    throw Error(path, "PROJ cannot transform its CRS '" + crs + "' to WGS 84: " +
                          proj_context_errno_string(proj.ctx, proj_context_errno(proj.ctx)));
  auto toGeo = [&](double x, double y, double z) {
    const PJ_COORD out = proj_trans(proj.pj, PJ_FWD, proj_coord(x, y, z, 0.0));
    if (!std::isfinite(out.xyz.x) || !std::isfinite(out.xyz.y) || std::abs(out.xyz.y) > 90.0)
      throw Error(path, "PROJ cannot place the origin of CRS '" + crs + "' on the Earth");
    return DVec3(out.xyz.x, out.xyz.y, std::isfinite(out.xyz.z) ? out.xyz.z : z);
  };
  const DVec3 o = toGeo(origin[0], origin[1], origin[2]);
  const DVec3 n = toGeo(origin[0], origin[1] + 100.0, origin[2]);
  GeoOrigin g;
  g.lon_deg = o.x;
  g.lat_deg = o.y;
  g.height_m = o.z;
  // The grid-north point in the origin's east-north-up frame.
  const DMat4 enu = enuTransform(g);
  const DVec3 d = geodeticToEcef(n.x, n.y, o.z) - geodeticToEcef(o.x, o.y, o.z);
  const double east = glm::dot(d, DVec3(enu[0])), north = glm::dot(d, DVec3(enu[1]));
  g.grid_rotation_rad = std::atan2(-east, north);
  return g;
}

}  // namespace farfield::store
