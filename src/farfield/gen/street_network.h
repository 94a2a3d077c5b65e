// Procedural street network: a planar street graph (irregular grid, some diagonal avenues and curved streets,
// junctions of degree 2-5, street widths by class) whose bounded faces are the city blocks.
#pragma once

#include <cstdint>
#include <vector>

#include "farfield/core/polygon2d.h"
#include "farfield/urban/street_graph.h"

namespace farfield::gen {

struct StreetNetworkOptions {
  int blocks = 100;             // target number of bounded faces (blocks); the result is within 10% of it
  uint64_t seed = 1;
  float block_size = 90.0f;     // mean distance between parallel streets, metres
  bool diagonal_avenues = true;
  bool curved_streets = true;
};

// Deterministic for given options. Throws farfield::Error when options are out of range (blocks < 1, ...).
urban::StreetGraph generateStreetNetwork(const StreetNetworkOptions& options);

// The buildable area of a block: a bounded face of the graph inset by half the width of each street around it.
struct BlockFootprint {
  uint32_t face = 0;        // face id in the street graph
  Polygon2 footprint;       // counter-clockwise, metres; empty blocks (collapsed by the inset) are not listed
};
std::vector<BlockFootprint> buildableBlocks(const urban::StreetGraph& graph);
// The buildable area of one bounded face (as in buildableBlocks); empty when it collapses or for the outer face.
Polygon2 buildableFootprint(const urban::StreetGraph& graph, uint32_t face);

}  // namespace farfield::gen
