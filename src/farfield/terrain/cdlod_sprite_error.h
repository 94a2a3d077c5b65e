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
#include <deque>
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
  // What a measure keeps of one sampled cell. Stand-in heights and C' are tagged with what they were made from.
  struct Cell {
    DVec3 c_prime{0.0};    // C' from the node's eye1, where `eye` is the node's eye_generation
    float z[5] = {};       // its corners' heights, then its centre's
    uint64_t version = 0;  // have == 2: the heights version of the stand-ins
    uint32_t eye = 0;      // the node's eye_generation when c_prime was made; 0: never
    uint8_t have = 0;      // 0: none; 1: z holds the grid's own heights; 2: heights that stand in
    uint8_t projected = 0;  // 1: c_prime; 2: none (spriteProjection failed)
  };
  // One sample of a node's cells, every k-th from `first` (cells by rank in the patch's Morton order, over its cells
  // inside the grid: cellOrder), held in sample order: a measure reads a few hundred cells of some 80 nodes after the
  // rasterizer's threads have evicted them from the caches, and cells in one run are streamed where cells scattered
  // over whole nodes cost a miss each (a third of a 0.2 ms measure on the 16,385^2 flight).
  struct Sampling {
    size_t first = 0, k = 0;  // k == 0: unused
    uint64_t used = 0;        // the last measure that used it
    std::vector<Cell> cells;  // cell first + j k at j
  };
  // A node's share of the sample changes with the eye's distance: its last few samplings are held, and a new one
  // starts with the cells the others hold.
  static constexpr size_t kSamplings = 3;
  struct Held {
    uint64_t used = 0;  // the last measure that sampled it
    size_t count = 0;   // its cells inside the grid
    Box3 box;           // the terrain's nodeBox and nodeError
    float error = 0.0f;
    const std::vector<uint32_t>* order = nullptr;  // cellOrder of its shape
    DVec3 eye1{0.0};    // the v1 of the cells' c_prime
    uint32_t eye_generation = 0;
    Sampling samplings[kSamplings];
  };
  Sampling& sampling(Held& held, size_t first, size_t k);
  // The cells of a node of columns x rows cells inside the grid (at most patch_cells each), in the patch's Morton
  // order: x | y << 16 at each rank. Made once per shape (interior nodes are all one shape).
  const std::vector<uint32_t>& cellOrder(int patch_cells, int columns, int rows);
  struct Order {
    int patch_cells, columns, rows;
    std::vector<uint32_t> cells;
  };
  std::deque<Order> orders_;  // a deque: the strata point at its elements while more are made
  std::unordered_map<Key, Held, KeyHash> held_;  // node-based: a Held stays where it is until erased
  struct Recent {
    Key key;
    Held* held;
  };
  std::vector<Recent> recent_, recent_next_;  // the last measure's nodes in its order; this measure's
  uint64_t measure_ = 0;
  uint32_t eye_generations_ = 0;
  Counters counters_;
  std::vector<IVec2> points_;                       // the grid points asked for in a measure
  std::vector<Cell*> asked_;                        // whose: the cell of each 5 points
  std::vector<float> z_;
  std::vector<uint8_t> own_;
};

}  // namespace farfield::terrain
