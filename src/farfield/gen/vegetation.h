// Procedural vegetation: seeded trees with many leaf triangles (where billboards belong, steed-ibr-impostors-lecture
// part 2, "the simplest impostor: the billboard ... nice trick to render trees"), rows of street trees along the
// blocks, parks, and a forest on rolling ground (a scene that is not a city).
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "farfield/core/bounds.h"
#include "farfield/core/math.h"
#include "farfield/core/polygon2d.h"
#include "farfield/scene/scene.h"

namespace farfield::gen {

struct TreeOptions {
  float height = 8.0f;        // metres, base to crown top
  float crown_radius = 3.0f;  // horizontal radius of the crown ellipsoid, metres
  int leaves = 400;           // leaf triangles, 1..100000
  float leaf_size = 0.45f;    // leaf edge, metres
};

// One tree standing at `base` (world): a six-sided trunk up to mid-crown and `leaves` randomly oriented leaf
// triangles inside the crown ellipsoid (centre at 0.62 height, vertical radius 0.38 height), normals pointing away
// from the crown's centre so the crown is lit as a volume. Deterministic for the seed. Throws farfield::Error for
// options out of range or a non-finite base.
struct TreeMeshes {
  scene::Mesh trunk;
  scene::Mesh crown;
};
TreeMeshes makeTree(const TreeOptions& options, uint64_t seed, const Vec3& base);

struct VegetationMaterials {
  uint32_t bark = 0;
  uint32_t leaves = 0;  // double-sided
};
VegetationMaterials addVegetationMaterials(scene::Scene& scene);

// Trees along the edges of counter-clockwise block footprints, `offset` metres outside each edge (on the street's
// margin), one every `spacing` metres (edges shorter than spacing get none; none within 4 m of a corner).
std::vector<Vec2> streetTreeSites(std::span<const Polygon2> footprints, float spacing, float offset);
// Trees scattered in a polygon with `per_square_metre` density, at least `min_gap` metres apart, `margin` metres
// inside its edges (dart throwing, deterministic for the seed).
std::vector<Vec2> parkTreeSites(const Polygon2& polygon, float per_square_metre, float min_gap, float margin,
                                uint64_t seed);

// Adds one object per site (name "tree", parts: trunk and crown) standing on ground(site), with size and leaf count
// varied per tree around `base` (height and crown radius 0.8..1.25 of it). Returns the ids of the added objects.
std::vector<uint32_t> addTrees(scene::Scene& scene, std::span<const Vec2> sites,
                               const std::function<float(Vec2)>& ground, const TreeOptions& base, uint64_t seed,
                               const VegetationMaterials& materials);

struct ForestOptions {
  float size = 400.0f;        // square side, metres
  int trees = 600;            // 1..200000
  float relief = 12.0f;       // height of the rolling ground's hills, metres
  TreeOptions tree;
  uint64_t seed = 1;
};
// A forest on rolling ground: object 1 is the ground (a grid, about 4 m cells), then one object per tree, trees
// scattered at least 3 m apart. Throws farfield::Error for options out of range.
scene::Scene generateForest(const ForestOptions& options);
// Height of the forest's ground at p (metres).
float forestGroundHeight(const ForestOptions& options, Vec2 p);

}  // namespace farfield::gen
