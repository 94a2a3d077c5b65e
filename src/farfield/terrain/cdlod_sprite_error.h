// Equation 2's sample over a CDLOD mesh (sprite_error.h) kept from one measure to the next.
//
// Along a path the low mesh's nodes change slowly (74 of 79 nodes a frame the previous frame's on the 16,385^2
// flight), though each node's share of the sample moves; and a cell's C' depends on the keyframe's viewpoint v1
// alone, not on the novel one. So every sampled cell of a node keeps its five grid points' heights while the node is
// in the mesh, and its C' while v1 stays: a measure asks the terrain only for the cells it never sampled before, and
// projects only those, or all of them after a new keyframe; theta and the magnification (v2's) are computed again.
// On a paged terrain the heights were the metric's largest cost: scattered over megabytes of pages that the
// rasterizer's threads evicted from the caches between frames. A measure equals spriteError's for the same arguments
// exactly (the same cells, the same arithmetic in the same order) while the heights it was given do not change. A
// height the terrain gave from its overview (its page not held) is kept while the terrain's heights version stays
// (GpuLodTerrain::heightsVersion: it changes when a page's heights come), and asked for again after; a cell whose
// page was evicted keeps the grid's own heights it had (where a fresh measure would have the overview's).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <unordered_map>
#include <vector>

#include "farfield/core/math.h"
#include "farfield/terrain/cdlod.h"
#include "farfield/terrain/sprite_error.h"

namespace farfield::terrain {

class CdlodSpriteError {
 public:
  struct Counters {
    size_t measures = 0;
    size_t cells_kept = 0;        // sampled cells whose heights came from an earlier measure
    size_t cells_gathered = 0;    // sampled cells whose heights were asked for
    size_t projections_kept = 0;  // sampled cells whose C' came from an earlier measure (the same v1)
  };

  // spriteError(lod, heights, nodes, v1, v2, max_quadrants), keeping what the next measure can reuse. lod must be the
  // terrain of every measure (clear() before another).
  // heights_version: the version of the heights that stand in for the grid's own (those `heights` marks 0).
  SpriteError measure(const CdlodTerrain& lod, const GridHeightsFn& heights, uint64_t heights_version,
                      std::span<const CdlodNode> nodes, const Vec3& v1, const Vec3& v2, size_t max_quadrants = 1024);
  // Forgets every kept node.
  void clear();

  const Counters& counters() const { return counters_; }
  size_t heldNodes() const { return held_.size(); }
  // A node is forgotten once this many measures went by without it.
  static constexpr uint64_t kKeepMeasures = 4;

 private:
  struct Key {
    int level, x, y;
    bool operator==(const Key&) const = default;
  };
  struct KeyHash {
    size_t operator()(const Key& key) const;
  };
  // A node's cells, by index in the patch (row by row over its cells inside the grid).
  struct Held {
    uint64_t used = 0;          // the last measure that sampled it
    std::vector<float> z;       // 5 a cell: its corners' heights, then its centre's
    std::vector<uint8_t> have;  // 1: z holds the grid's own heights; 2: heights that stand in, of `version`
    uint64_t version = 0;
    DVec3 eye1{0.0};            // the v1 of c_prime
    std::vector<DVec3> c_prime;  // a cell's C' from eye1
    std::vector<uint8_t> projected;  // 0: not from eye1; 1: c_prime; 2: none (spriteProjection failed)
  };
  std::unordered_map<Key, Held, KeyHash> held_;
  uint64_t measure_ = 0;
  Counters counters_;
  std::vector<IVec2> points_;                       // the grid points asked for in a measure
  std::vector<std::pair<Held*, size_t>> asked_;     // whose: the node and cell of each 5 points
  std::vector<float> z_;
  std::vector<uint8_t> own_;
};

}  // namespace farfield::terrain
