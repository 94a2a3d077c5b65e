// Procedural city: a planar street graph whose faces are blocks, buildings filling each block from its footprint
// inward (extruded footprints with facade detail as real geometry), a few landmarks, an optional hill.
#pragma once

#include <cstdint>
#include <string>

#include "farfield/scene/scene.h"
#include "farfield/urban/street_graph.h"

namespace farfield::gen {

enum class ObjectGrouping { Blocks, Buildings };  // one object per block (Sillion, Decoret) or per building (Jeschke)

struct CityOptions {
  int blocks = 100;          // number of blocks (faces of the street graph), 10..50000
  uint64_t seed = 1;
  int detail = 1;            // facade detail level 0..4: 0 = plain boxes, higher = windows, ledges, balconies
  bool hill = false;         // a hill in the middle of the city (as Montmartre), so panoramic views open up
  ObjectGrouping objects = ObjectGrouping::Blocks;
};

struct City {
  scene::Scene scene;            // object 1 is the ground (streets and terrain); then blocks or buildings
  urban::StreetGraph streets;
  // For each object id (index id - 1): the street-graph face (block) it stands in, or -1 (ground).
  std::vector<int32_t> object_block;
};

// Deterministic for a given options value. Throws farfield::Error for options out of range.
City generateCity(const CityOptions& options);

// Writes scene to `glb_path` and the street graph to the `.streets.json` next to it
// (city.glb -> city.streets.json).
std::string streetsPathFor(const std::string& glb_path);

}  // namespace farfield::gen
