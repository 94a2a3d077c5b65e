// Procedural crowd: N agents walking the sidewalks of a city's street graph, each on its own loop around a block
// (the strip just outside the block's kerb line), in its own direction, at its own speed and animation phase, with
// a model chosen among several, a colour tint and an outfit: a row of 16 colour-region tints (the lecture's colour
// variety). Deterministic for a seed.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "farfield/core/math.h"
#include "farfield/core/polygon2d.h"
#include "farfield/urban/street_graph.h"

namespace farfield::gen {

struct CrowdOptions {
  size_t agents = 1000;
  uint64_t seed = 1;
  // Share of agents of each model (index = model); normalised; at least one entry.
  std::vector<float> model_shares{0.7f, 0.3f};
  float sidewalk_offset = 1.5f;  // metres from the kerb line (block boundary inset by half the street width) into
                                 // the street: where agents walk
  float min_speed = 0.9f;        // m/s
  float max_speed = 1.6f;
  size_t outfits = 32;           // rows of region tints to draw from (at least 1)
  // Ground height under the sidewalks; null = flat ground at z = 0.
  std::function<float(float x, float y)> ground_height;
};

// A sidewalk loop around one block, counter-clockwise.
struct SidewalkRoute {
  uint32_t face = 0;            // the block (street-graph face)
  Polygon2 kerb;                // the block's kerb line (its buildable footprint)
  Polygon2 loop;                // where agents walk
  std::vector<float> distance;  // arc length at each loop vertex (distance[0] = 0)
  float length = 0.0f;
};

struct CrowdAgent {
  uint32_t model = 0;
  uint32_t route = 0;
  float start = 0.0f;    // arc length at t = 0, metres
  float speed = 1.2f;    // m/s
  int direction = 1;     // +1 counter-clockwise, -1 clockwise
  float phase = 0.0f;    // animation phase at t = 0, [0, 1)
  Vec4 tint{1.0f};       // colour modulation, alpha 1
  uint32_t outfit = 0;   // row of Crowd::region_tints
};

struct Crowd {
  std::vector<SidewalkRoute> routes;
  std::vector<CrowdAgent> agents;
  std::function<float(float x, float y)> ground_height;
  // Outfits x kCrowdRegions tints (outfit o, region r at o * kCrowdRegions + r): muted colours, a third of the
  // regions left white so that the model's own texture shows there. Depends on the seed and outfit count only.
  std::vector<Vec4> region_tints;
};

inline constexpr size_t kCrowdRegions = 16;  // = scene::kColorRegions

struct AgentPose {
  Vec3 position{0.0f};  // feet, metres
  float heading = 0.0f;  // radians about +z, the walking direction
  float walked = 0.0f;   // metres since t = 0 (for the animation phase)
};

// Agents spread over the routes in proportion to their length. Throws farfield::Error for a graph without blocks
// that leave a sidewalk, no model shares, non-positive speeds or a negative offset.
Crowd generateCrowd(const urban::StreetGraph& streets, const CrowdOptions& options);

// The region-tint table of generateCrowd (Crowd::region_tints) for a seed and outfit count.
std::vector<Vec4> crowdRegionTints(uint64_t seed, size_t outfits);

// Where agent i is at time t (seconds).
AgentPose agentPose(const Crowd& crowd, size_t i, float t);

}  // namespace farfield::gen
