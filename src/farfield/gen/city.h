// Procedural city: a planar street graph whose faces are blocks, buildings filling each block from its footprint
// inward (extruded footprints with facade detail as real geometry), a few landmarks, an optional hill or any ground
// (a terrain) under it all.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "farfield/scene/scene.h"
#include "farfield/urban/street_graph.h"

namespace farfield::gen {

enum class ObjectGrouping { Blocks, Buildings };  // one object per block (Sillion, Decoret) or per building (Jeschke)

struct CityOptions {
  int blocks = 100;          // number of blocks (faces of the street graph), 10..200000
  uint64_t seed = 1;
  int detail = 1;            // facade detail level 0..4: 0 = plain boxes, higher = windows, ledges, balconies
  bool hill = false;         // a hill in the middle of the city (as Montmartre), so panoramic views open up
  // Any ground instead (a terrain: a DEM or a fractal, apps' `gen city --terrain`): the height (metres) at a point
  // given relative to the centre of the street graph's bounds. Called from several threads at once (it must only
  // read). Not with `hill`. The ground mesh samples it every ground_cell metres (at most 1024 cells a side).
  std::function<float(Vec2)> ground;
  float ground_cell = 10.0f;
  ObjectGrouping objects = ObjectGrouping::Blocks;
  // Vegetation (gen/vegetation.h), off by default so the figures of cities without it stay valid: street trees
  // every tree_spacing metres along the blocks (on the street's margin) and park_share of the blocks (not landmarks)
  // turned into parks of scattered trees instead of buildings. One object per tree, after the blocks' objects.
  bool trees = false;
  float tree_spacing = 18.0f;   // metres, > 1
  float park_share = 0.1f;      // 0..1
  int tree_leaves = 300;        // leaf triangles per tree (about; varied per tree)
};

struct City {
  scene::Scene scene;            // object 1 is the ground (streets and terrain); then blocks or buildings
  urban::StreetGraph streets;
  // For each object id (index id - 1): the street-graph face (block) it stands in, or -1 (ground).
  std::vector<int32_t> object_block;
  Box2 bounds;                   // streets.bounds(): what cityGroundHeight() takes
  size_t buildings = 0;          // buildings generated, landmarks included
  size_t landmarks = 0;
  size_t skipped_blocks = 0;     // faces whose buildable area collapsed (street inset) or held no building
  size_t skipped_lots = 0;       // lots dropped as degenerate while subdividing blocks
  size_t trees = 0;              // tree objects (CityOptions::trees)
  size_t parks = 0;              // blocks turned into parks
};

// Deterministic for a given options value. Throws farfield::Error for options out of range.
// Materials: ground (asphalt), three facade tints, roof tiles, landmark stone (textures from textures.h). A block
// object has up to three parts (facades, roofs, landmark); a building object the parts of its building. Every
// object keeps its 2D footprint: the block's buildable footprint, or the building's footprint; the ground's is the
// ground rectangle. Big cities show progress on stderr (farfield/core/progress.h).
City generateCity(const CityOptions& options);

// Height of the ground (z, metres) at p for a city generated with `options`, whose street graph has the 2D bounds
// `city_bounds` (StreetGraph::bounds()). 0 everywhere without a hill or a ground; with a hill, a smooth bump (raised
// cosine) centred on the bounds; with a ground, that function at p - the bounds' centre. Camera paths use it to
// follow the ground; the ground mesh is a tessellation of it (within about 0.2 m for the hill) and buildings stand on
// it (their walls reach 1 m below the lowest ground under their footprint).
float cityGroundHeight(const CityOptions& options, const Box2& city_bounds, Vec2 p);

// Writes scene to `glb_path` and the street graph to the `.streets.json` next to it
// (city.glb or city.gltf -> city.streets.json).
std::string streetsPathFor(const std::string& glb_path);

}  // namespace farfield::gen
