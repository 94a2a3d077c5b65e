// City surfaces to meshes (see city_surfaces.h). The class colours are those Farfield has used for CityJSON since
// its first importer; appearance materials multiply their texture with white so the texture shows as it is.
#include "farfield/geodata/city_surfaces.h"

#include <cmath>
#include <limits>
#include <set>

#include "farfield/core/check.h"

namespace farfield::geodata {

namespace {

struct ClassStyle {
  const char* name;
  Vec4 colour;
};
constexpr ClassStyle kStyles[kClassCount] = {
    {"wall", {0.86f, 0.82f, 0.74f, 1.0f}},       {"roof", {0.72f, 0.32f, 0.24f, 1.0f}},
    {"ground surface", {0.38f, 0.36f, 0.34f, 1.0f}}, {"road", {0.33f, 0.33f, 0.35f, 1.0f}},
    {"land use", {0.66f, 0.68f, 0.50f, 1.0f}},   {"vegetation", {0.32f, 0.55f, 0.27f, 1.0f}},
    {"water", {0.26f, 0.46f, 0.70f, 1.0f}},      {"terrain", {0.58f, 0.52f, 0.42f, 1.0f}},
    {"structure", {0.62f, 0.62f, 0.64f, 1.0f}},
};

}  // namespace

CityCategory cityCategoryOf(const std::string& type) {
  if (type == "Building") return CityCategory::Building;
  if (type.rfind("Building", 0) == 0) return CityCategory::BuildingPart;  // BuildingPart, BuildingInstallation, ...
  // CityJSON and CityGML names (TransportSquare / Square, TINRelief / ReliefFeature, ...).
  static const std::set<std::string> ground = {"Road",     "Railway",       "TransportSquare", "Square",
                                               "Track",    "Waterway",      "LandUse",         "PlantCover",
                                               "WaterBody", "TINRelief",    "ReliefFeature",   "ReliefComponent",
                                               "TransportationObject"};
  if (ground.count(type)) return CityCategory::Ground;
  return CityCategory::Other;
}

std::optional<SurfaceClass> semanticSurfaceClass(const std::string& s) {
  if (s == "RoofSurface") return kRoof;
  if (s == "WallSurface" || s == "ClosureSurface" || s == "OuterCeilingSurface" || s == "Window" || s == "Door" ||
      s == "InteriorWallSurface" || s == "CeilingSurface")
    return kWall;
  if (s == "GroundSurface" || s == "OuterFloorSurface" || s == "FloorSurface") return kGroundSurface;
  if (s == "TrafficArea" || s == "TransportationMarking" || s == "TransportationHole") return kRoad;
  if (s == "AuxiliaryTrafficArea") return kLand;
  if (s == "WaterSurface" || s == "WaterGroundSurface" || s == "WaterClosureSurface") return kWater;
  return std::nullopt;
}

SurfaceClass defaultSurfaceClass(const std::string& type) {
  if (type == "Road" || type == "Railway" || type == "TransportSquare" || type == "Square" || type == "Track" ||
      type == "TransportationObject")
    return kRoad;
  if (type == "LandUse") return kLand;
  if (type == "PlantCover" || type == "SolitaryVegetationObject") return kVegetation;
  if (type == "WaterBody" || type == "Waterway") return kWater;
  if (type == "TINRelief" || type == "ReliefFeature" || type == "ReliefComponent") return kTerrain;
  return kStructure;
}

SurfaceClass classByNormal(const DVec3& n) { return n.z > 0.3 ? kRoof : (n.z < -0.7 ? kGroundSurface : kWall); }

CityMaterials::CityMaterials(scene::Scene& scene) : scene_(scene) {
  for (int c = 0; c < kClassCount; ++c) {
    scene::Material m;
    m.name = kStyles[c].name;
    m.base_color = kStyles[c].colour;
    classes_[c] = scene_.addMaterial(std::move(m));
  }
}

uint32_t CityMaterials::forTexture(const std::string& key, std::shared_ptr<const image::ColorImage> texture,
                                   const std::string& path) {
  if (auto it = textures_.find(key); it != textures_.end()) return it->second;
  scene::Material m;
  m.name = key;
  m.texture = std::move(texture);
  m.texture_path = path;
  return textures_[key] = scene_.addMaterial(std::move(m));
}

uint32_t CityMaterials::forColour(const std::string& key, const std::string& name, const Vec4& rgba) {
  if (auto it = colours_.find(key); it != colours_.end()) return it->second;
  scene::Material m;
  m.name = name;
  m.base_color = rgba;
  return colours_[key] = scene_.addMaterial(std::move(m));
}

bool triangulateCityFace(const CityFace& face, PolygonTriangulation& out, DVec3* normal) {
  out = PolygonTriangulation();
  return triangulateFace3(face.rings, out, normal);
}

size_t appendCityFace(const CityFace& face, const PolygonTriangulation& t, DVec3 normal, bool flip, scene::Mesh& m) {
  const bool textured = !face.uvs.empty();
  FF_CHECK(!textured || face.uvs.size() == face.rings.size());
  FF_CHECK_MSG(m.uvs.size() == (textured ? m.positions.size() : 0),
               "a mesh holds either textured or untextured faces");
  if (flip) normal = -normal;
  const Vec3 n = Vec3(normal);
  const uint32_t first = uint32_t(m.positions.size());
  for (size_t r = 0; r < face.rings.size(); ++r) {
    FF_CHECK(!textured || face.uvs[r].size() == face.rings[r].size());
    for (size_t i = 0; i < face.rings[r].size(); ++i) {
      m.positions.emplace_back(Vec3(face.rings[r][i]));
      m.normals.push_back(n);
      if (textured) m.uvs.push_back(face.uvs[r][i]);
    }
  }
  for (const DVec3& p : t.extra) {
    m.positions.emplace_back(Vec3(p));
    m.normals.push_back(n);
    if (!textured) continue;
    // Only where rings cross (malformed input): the uv of the nearest ring vertex.
    double best = std::numeric_limits<double>::max();
    Vec2 uv(0.0f);
    for (size_t r = 0; r < face.rings.size(); ++r)
      for (size_t i = 0; i < face.rings[r].size(); ++i) {
        const double d = glm::distance(face.rings[r][i], p);
        if (d < best) best = d, uv = face.uvs[r][i];
      }
    m.uvs.push_back(uv);
  }
  for (size_t i = 0; i + 2 < t.indices.size(); i += 3) {
    if (flip)
      m.indices.insert(m.indices.end(), {first + t.indices[i], first + t.indices[i + 2], first + t.indices[i + 1]});
    else
      m.indices.insert(m.indices.end(), {first + t.indices[i], first + t.indices[i + 1], first + t.indices[i + 2]});
  }
  return t.indices.size() / 3;
}

}  // namespace farfield::geodata
