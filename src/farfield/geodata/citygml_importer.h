// The CityGML reader (citygml_import.h) in its parts: parsing, the CRS and the two passes (citygml_import.cpp),
// each root object's LoD and polygons (citygml_lod_choice.cpp), polygons to triangles (citygml_faces.cpp), their
// textures and materials (citygml_appearance.cpp) and the scene objects, streets and blocks (citygml_objects.cpp).
// Internal to the geodata module: only src/farfield/geodata/citygml_*.cpp include it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <citygml/citymodel.h>
#include <citygml/cityobject.h>
#include <citygml/polygon.h>

#include "farfield/core/error.h"
#include "farfield/geodata/city_surfaces.h"
#include "farfield/geodata/citygml_import.h"
#include "farfield/scene/import.h"

namespace farfield::geodata::citygml_import {

namespace fs = std::filesystem;
using CityObjectType = citygml::CityObject::CityObjectsType;

// Skip reasons.
constexpr const char* kNoExterior = "polygons without an exterior ring";
constexpr const char* kTooFew = "polygons with fewer than 3 distinct vertices";
constexpr const char* kNoArea = "polygons without area";
constexpr const char* kBadCoordinate = "polygons with non-finite coordinates";
constexpr const char* kImplicit = "implicit geometries (templates not supported)";
constexpr const char* kNoGeometry = "objects without usable geometry";
constexpr const char* kLodFiltered = "objects without geometry at the requested LoD";

// A polygon chosen for a root object, with how to colour it when it has no appearance.
struct Surface {
  const citygml::Polygon* polygon;
  std::optional<SurfaceClass> semantic;
  SurfaceClass fallback;
  bool by_normal;
};

// A root city object: what it draws and what it counts as.
struct Unit {
  const citygml::CityObject* object;
  std::string type;
  CityCategory category;
  std::vector<Surface> surfaces;
  size_t parts = 0;
  std::optional<unsigned> lod;
  bool lod_filtered = false;
};

// The two passes over a parsed CityModel into a CityGmlScene.
class Importer {
 public:
  Importer(const std::string& source, const std::string& base_dir, const CityGmlImportOptions& options,
           CityGmlScene& result)
      : source_(source), base_dir_(base_dir), options_(options), result_(result), st_(result.stats),
        texture_files_(st_.import) {}

  void run(const citygml::CityModel& model);

 private:
  // The CRS, and the error of a document without a usable surface (citygml_import.cpp).
  Error noSurface() const;
  void readCrs(const citygml::CityModel& model);

  // The first pass (citygml_lod_choice.cpp).
  void chooseSurfaces(const citygml::CityObject& root);

  // Faces (citygml_faces.cpp) and their appearances (citygml_appearance.cpp).
  bool ringOf(const citygml::LinearRing& ring, std::vector<DVec3>& out, bool& closed) const;
  std::optional<uint32_t> textureOf(const citygml::Polygon& p, const std::vector<const citygml::LinearRing*>& rings,
                                    const std::vector<bool>& closed, CityFace& face);
  std::optional<uint32_t> materialOf(const citygml::Polygon& p);
  void face(const Surface& s, std::map<uint32_t, scene::Mesh>& meshes, std::vector<Vec2>& hull,
            std::vector<std::vector<std::vector<DVec2>>>* plan);

  void skip(const char* reason) { ++st_.skipped[reason]; }

  // A built root object, before it becomes a scene object (alone or in its block).
  struct Built {
    const Unit* unit;
    std::map<uint32_t, scene::Mesh> meshes;
    std::vector<Vec2> hull;
  };

  // The scene objects (citygml_objects.cpp).
  void build();
  static void addParts(scene::Scene& scene, std::map<uint32_t, scene::Mesh>& meshes, scene::Object& o);
  void perObject(std::vector<Built>& built);
  void byBlock(std::vector<Built>& built);

  const std::string& source_;
  const std::string& base_dir_;
  const CityGmlImportOptions& options_;
  CityGmlScene& result_;
  CityGmlStats& st_;
  scene::TextureFiles texture_files_;
  CityMaterials* materials_ = nullptr;
  std::vector<Unit> units_;
  DVec3 origin_{0.0};
  DVec3 used_min_{std::numeric_limits<double>::max()}, used_max_{std::numeric_limits<double>::lowest()};
};

}  // namespace farfield::geodata::citygml_import
