// Surfaces of city models (CityJSON, CityGML) to scene meshes, shared by both importers: the object categories and
// semantic surface classes of the two formats (they use the same type names), one material per class colour and
// per appearance (a texture image or a material colour), and planar faces with holes triangulated in their plane
// (triangulate.h) and appended to a mesh with their normals and texture coordinates.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "farfield/core/math.h"
#include "farfield/geodata/triangulate.h"
#include "farfield/image/image.h"
#include "farfield/scene/scene.h"

namespace farfield::geodata {

// What a root city object counts as (import statistics, options that leave ground or other objects out).
enum class CityCategory { Building, BuildingPart, Ground, Other };
CityCategory cityCategoryOf(const std::string& type);  // "Building", "BuildingPart", "Road", "LandUse", ...

// Colour classes of surfaces: one material each.
enum SurfaceClass : int {
  kWall = 0, kRoof, kGroundSurface, kRoad, kLand, kVegetation, kWater, kTerrain, kStructure, kClassCount
};
// The class of a semantic surface type ("RoofSurface", "WallSurface", "TrafficArea", ...); nullopt when unknown.
std::optional<SurfaceClass> semanticSurfaceClass(const std::string& semantic_type);
// The class of an object type's surfaces when no semantics say otherwise (buildings: see classByNormal).
SurfaceClass defaultSurfaceClass(const std::string& object_type);
// Building surfaces without semantics: facing up is roof, down is ground, else wall (unit normal).
SurfaceClass classByNormal(const DVec3& normal);

// Materials of an imported city: the class colours (added by the constructor, named "wall", "roof", ...), then one
// per texture image and per appearance colour, added the first time a key is seen.
class CityMaterials {
 public:
  explicit CityMaterials(scene::Scene& scene);
  uint32_t forClass(SurfaceClass c) const { return classes_[c]; }
  // A white material showing `texture`; `key` identifies the image in the file (its path), `path` is recorded as
  // the material's texture_path (empty for a placeholder).
  uint32_t forTexture(const std::string& key, std::shared_ptr<const image::ColorImage> texture, const std::string& path);
  // A material of colour `rgba` (linear 0..1); `key` identifies it in the file, `name` names it.
  uint32_t forColour(const std::string& key, const std::string& name, const Vec4& rgba);

 private:
  scene::Scene& scene_;
  uint32_t classes_[kClassCount] = {};
  std::map<std::string, uint32_t> textures_, colours_;
};

// One planar face: outer ring then holes, each without a repeated closing vertex, in local coordinates (metres,
// small), with optional texture coordinates per ring vertex (Farfield's convention: (0, 0) at the top left).
struct CityFace {
  std::vector<std::vector<DVec3>> rings;
  std::vector<std::vector<Vec2>> uvs;  // empty (untextured) or one list per ring, each as long as its ring
};

// Triangulates `face`; false (and nothing in `out`) for a face without area or with a non-finite coordinate.
// `normal` receives the unit normal, oriented like the outer ring (counter-clockwise around it).
bool triangulateCityFace(const CityFace& face, PolygonTriangulation& out, DVec3* normal);

// Appends a triangulated face to `mesh` with flat normals (and its uvs when the face has them; vertices the
// triangulation added take the uv of the nearest ring vertex). `flip` reverses the winding and the normal (a
// surface whose file orientation is negative). Returns the number of triangles added.
size_t appendCityFace(const CityFace& face, const PolygonTriangulation& t, DVec3 normal, bool flip, scene::Mesh& mesh);

}  // namespace farfield::geodata
