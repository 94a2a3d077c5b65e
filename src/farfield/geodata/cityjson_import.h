// CityJSON (1.0, 1.1, 2.0) import: buildings with their parts, roads, land use, vegetation, water, terrain and
// other city objects as scene objects. Every surface (LoD1 or LoD2; Solid, CompositeSolid, MultiSolid,
// MultiSurface, CompositeSurface) is triangulated in its plane with its holes (triangulate.h). Surfaces are
// coloured by their semantic class (RoofSurface, WallSurface, GroundSurface, ...) when the file gives one; building
// surfaces without semantics are classified by their normal (facing up: roof, down: ground, else wall).
//
// Appearances: a surface with a texture in the chosen theme (appearance.textures, "vertices-texture" and the
// geometry's per-ring "texture" values) gets one material per texture image, its file read relative to the CityJSON
// file; a surface without one but with a material (appearance.materials, diffuseColor and transparency) gets that
// colour; the rest their class colour. A texture file that is missing or cannot be decoded is a counted warning
// (stats.import) with a checkerboard in its place. Themes: CityJsonImportOptions::theme, else CityJSON 1.0's
// "default-theme-texture"/"default-theme-material", else the first theme by name. The three versions store
// appearances alike; 1.0 alone has the default themes and numeric LoDs, 1.1 and 2.0 require `transform`.
//
// Coordinates: the file's `transform` (scale, translate) is applied in double precision, then the centre of the
// vertices' bounding box, rounded to whole metres (z kept at 0), is subtracted so that the scene's floats keep
// millimetre precision (EPSG:7415 coordinates are about 85,000 / 445,000 m). GeoReference gives the offset back.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "farfield/core/bounds.h"
#include "farfield/geodata/projection.h"
#include "farfield/scene/import.h"
#include "farfield/scene/scene.h"

namespace farfield::geodata {

struct CityJsonImportOptions {
  // Per object, the geometry of the highest LoD not above max_lod (all LoDs when unset). Objects with no geometry
  // at or below it are counted as skipped.
  std::optional<double> max_lod;
  bool ground_objects = true;  // roads, railways, land use, vegetation, water, terrain
  bool other_objects = true;   // bridges, tunnels, city furniture, generic objects, unknown (extension) types
  // Appearance theme for textures and materials (empty: see the file comment). A theme the file does not have is
  // an error listing those it has.
  std::string theme;
};

struct CityJsonStats {
  std::string version;                    // "2.0"
  size_t vertices = 0;                    // in the file's "vertices"
  size_t bad_vertices = 0;                // vertices that are not three finite numbers (faces using them skipped)
  size_t city_objects = 0;                // in the file
  size_t buildings = 0;                   // Building objects imported (parts go into their building)
  size_t building_parts = 0;              // BuildingPart objects imported
  size_t ground_objects = 0;              // roads, land use, ... imported
  size_t other_objects = 0;               // bridges, generic objects, ... imported
  std::map<std::string, size_t> objects_by_type;  // imported city objects per CityJSON type
  size_t surfaces = 0;                    // surfaces triangulated
  size_t semantic_surfaces = 0;           // of which with a semantic class from the file
  size_t inferred_surfaces = 0;           // building surfaces classified by their normal
  size_t holes = 0;                       // inner rings
  size_t textured_surfaces = 0;           // surfaces drawn with a texture (placeholders included)
  size_t material_surfaces = 0;           // surfaces drawn in an appearance material's colour
  size_t bad_texture_references = 0;      // texture references that do not fit their surface (drawn untextured)
  size_t bad_texture_vertices = 0;        // "vertices-texture" entries that are not two finite numbers
  std::vector<std::string> texture_themes, material_themes;  // in the file, by name
  std::string texture_theme, material_theme;                  // used (empty: none)
  scene::ImportStats import;              // missing or unreadable texture files (checkerboard placeholders)
  uint64_t triangles = 0;
  std::map<std::string, size_t> skipped;  // per reason: faces and objects that could not be used
  double read_s = 0.0, build_s = 0.0;

  size_t skippedTotal() const;
};

struct CityJsonScene {
  scene::Scene scene;       // one object per root city object (a building with its parts is one object)
  GeoReference reference;   // scene + reference.origin = file coordinates (reference.crs from the metadata)
  // Bounds of the vertices used by imported surfaces, in file coordinates (after the transform, double precision).
  DVec3 file_min{0.0}, file_max{0.0};
  CityJsonStats stats;
};

// Throws farfield::Error naming the file for unreadable JSON, a document that is not CityJSON, an unsupported
// version (listing the supported ones), a malformed `transform` or `vertices` array, or when no surface could be
// imported. Bad faces (vertex indices out of range, too few vertices, no area) and bad objects are skipped and
// counted per reason.
CityJsonScene importCityJson(const std::string& path, const CityJsonImportOptions& options = {});

}  // namespace farfield::geodata
