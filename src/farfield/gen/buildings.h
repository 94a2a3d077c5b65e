// Buildings of one city block, built "from the footprint inward": the block's boundary is cut into lots along each
// street edge (lot width 8-25 m, depth 10-20 m toward the interior), leaving a courtyard in the middle; each lot is
// an extruded footprint with a flat or pitched roof and facade detail as real geometry. Landmarks (towers, a church
// with a spire) replace the ordinary buildings of a few blocks.
//
// Detail levels (appendBuildingGeometry): 0 = plain extrusions; 1 = + a ledge above the ground floor and a cornice;
// 2 = + a recessed window per bay and floor; 3 = + window frames, sills and balconies; 4 = + a ledge at every floor,
// window mullions and narrower bays. Only street and courtyard walls get ledges and windows; party walls between
// lots stay plain.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "farfield/core/polygon2d.h"
#include "farfield/scene/mesh.h"

namespace farfield::gen {

// Deterministic random numbers for the generators (splitmix64). Same sequence on every platform: no std
// distributions, whose output differs between standard libraries.
class Rng {
 public:
  explicit Rng(uint64_t seed) : state_(seed) {}
  uint64_t next() {
    uint64_t z = (state_ += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  float uniform() { return float(next() >> 40) * (1.0f / 16777216.0f); }  // [0, 1)
  float uniform(float lo, float hi) { return lo + (hi - lo) * uniform(); }
  int uniformInt(int lo, int hi) { return lo + int(next() % uint64_t(hi - lo + 1)); }  // [lo, hi]
  float normal();                                                                      // standard normal (Box-Muller)

 private:
  uint64_t state_;
};
// Seed of an independent stream: for block `b` of a city with seed `s`, mixSeed(s, b).
uint64_t mixSeed(uint64_t a, uint64_t b);

enum class WallKind : uint8_t { Street, Courtyard, Party };
enum class RoofShape : uint8_t { Flat, Gable };
enum class LandmarkKind : uint8_t { None, Tower, Church };

struct Building {
  Polygon2 footprint;           // counter-clockwise, metres, inside the block footprint
  std::vector<WallKind> walls;  // one per footprint edge i = (footprint[i], footprint[i + 1])
  float base_z = 0.0f;          // bottom of the walls (at or below the ground under the footprint)
  float height = 0.0f;          // top of the walls (eaves) above base_z; a whole number of floors
  float floor_height = 3.2f;    // metres per floor: one facade texture tile vertically
  float bay_width = 3.2f;       // target width of a window bay: one facade texture tile horizontally
  RoofShape roof = RoofShape::Flat;
  int ridge_edge = -1;     // Gable (4-vertex footprints): eaves along edges ridge_edge and ridge_edge + 2
  float roof_rise = 0.0f;  // Gable: ridge above the eaves
  bool balconies = false;  // detail >= 3: balconies on the street walls above the ground floor
  LandmarkKind landmark = LandmarkKind::None;
  float top = 0.0f;  // highest point above base_z (ridge, spire tip); > height for pitched roofs

  int floors() const { return floor_height > 0.0f ? int(height / floor_height + 0.5f) : 0; }
};

struct LotOptions {
  float lot_width_min = 8.0f;  // along the street, metres
  float lot_width_max = 25.0f;
  float lot_depth_min = 10.0f;  // from the street toward the courtyard
  float lot_depth_max = 20.0f;
  float single_building_area = 700.0f;  // blocks smaller than this (m^2) become one building
  // Heights: lognormal (median * height_scale * exp(sigma * N(0,1))), clamped, then rounded to whole floors.
  // With the defaults about 3/4 of the buildings are 10-25 m and about 1% reach 40-80 m.
  float height_median = 15.5f;
  float height_sigma = 0.4f;
  float height_min = 6.0f;
  float height_max = 80.0f;
  float height_scale = 1.0f;  // per block (the city makes its centre taller)
  float gable_share = 0.4f;   // share of street lots with a pitched roof (when lower than 30 m)
};

struct BlockLayout {
  std::vector<Building> buildings;
  Polygon2 courtyard;    // the free interior left by the lots (empty when the block is one building)
  int skipped_lots = 0;  // lots dropped as degenerate (too small, self-intersecting after cleaning)
};

// Cuts a block footprint (counter-clockwise; inset from the streets already) into building lots. Deterministic for
// (block, seed, options). Blocks smaller than single_building_area, or too thin for lots of the minimum depth,
// become one building covering the block. A degenerate block (fewer than 3 distinct vertices, no area,
// self-intersecting) gives no buildings. All footprints lie inside the block and do not overlap.
BlockLayout layoutBlock(const Polygon2& block, uint64_t seed, const LotOptions& options = {});

// A landmark standing alone in a block (a plaza around it): Tower = stacked setback tiers and a mast, 130-190 m;
// Church = a nave with a pitched roof and a front tower with a spire, 95-120 m. Both are taller than any ordinary
// building (height_max 80 m). nullopt when the block cannot hold the footprint.
std::optional<Building> makeLandmark(LandmarkKind kind, const Polygon2& block, uint64_t seed);

// Where geometry goes: facades (walls, ledges, windows, balconies, gable ends), roofs, and landmark (everything of
// a landmark, in stone).
struct BuildingMeshes {
  scene::Mesh facades;
  scene::Mesh roofs;
  scene::Mesh landmark;

  void clear();
  size_t triangleCount() const { return facades.triangleCount() + roofs.triangleCount() + landmark.triangleCount(); }
};

// Appends the building's geometry (positions, flat normals, uvs; triangles counter-clockwise seen from outside).
// Facade uvs: u = metres along the wall / bay width, v = metres below the top of the floor grid / floor height,
// so the facade texture (textures.h) repeats once per window bay and floor. Roof uvs: metres / 4. Does not
// update the meshes' bounds. detail is clamped to 0..4.
void appendBuildingGeometry(const Building& building, int detail, BuildingMeshes& out);

// Ear-clipping triangulation of a simple polygon (either orientation): triangles as index triples into `polygon`,
// counter-clockwise. polygon.size() - 2 triangles for a simple polygon.
std::vector<uint32_t> triangulatePolygon(const Polygon2& polygon);

}  // namespace farfield::gen
