// Equation 2 over a CDLOD mesh's cells (sprite_error.h), with the sample kept between measures
// (cdlod_sprite_error.h).
#include "farfield/terrain/cdlod_sprite_error.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <iterator>

namespace farfield::terrain {

size_t CdlodSpriteError::KeyHash::operator()(const Key& key) const {
  uint64_t h = uint64_t(uint32_t(key.x)) * 0x9E3779B97F4A7C15ull;
  h ^= (uint64_t(uint32_t(key.y)) + 0x632BE59BD9B4E019ull + (h << 6) + (h >> 2)) * 0xC2B2AE3D27D4EB4Full;
  h ^= uint64_t(uint32_t(key.level)) << 56;
  return size_t(h ^ (h >> 29));
}

CdlodSpriteError::Sampling& CdlodSpriteError::sampling(Held& held, size_t first, size_t k) {
  Sampling* slot = &held.samplings[0];
  for (Sampling& s : held.samplings) {
    if (s.k == k && s.first == first) return s;
    if (s.used < slot->used) slot = &s;
  }
  // Strides are powers of two (measure): a cell is in another sampling where its offset from that one's first is a
  // multiple of its stride, a mask and a shift.
  std::vector<Cell> cells((held.count - std::min(first, held.count) + k - 1) / k);
  for (const Sampling& s : held.samplings) {
    if (s.k == 0) continue;
    const size_t mask = s.k - 1;
    const int shift = std::countr_zero(s.k);
    for (size_t j = 0; j < cells.size(); ++j) {
      const size_t c = first + j * k;
      if (cells[j].have == 0 && c >= s.first && ((c - s.first) & mask) == 0)
        cells[j] = s.cells[(c - s.first) >> shift];
    }
  }
  slot->first = first;
  slot->k = k;
  slot->cells = std::move(cells);
  return *slot;
}

const std::vector<uint32_t>& CdlodSpriteError::cellOrder(int patch_cells, int columns, int rows) {
  for (const Order& o : orders_)
    if (o.patch_cells == patch_cells && o.columns == columns && o.rows == rows) return o.cells;
  Order& o = orders_.emplace_back(Order{patch_cells, columns, rows, {}});
  o.cells.reserve(size_t(columns) * size_t(rows));
  // Morton codes over the patch (a power of two a side), each cell inside the grid in code order: even bits x, odd y.
  for (uint32_t code = 0; code < uint32_t(patch_cells) * uint32_t(patch_cells); ++code) {
    uint32_t x = 0, y = 0;
    for (int bit = 0; bit < 16; ++bit) {
      x |= ((code >> (2 * bit)) & 1u) << bit;
      y |= ((code >> (2 * bit + 1)) & 1u) << bit;
    }
    if (int(x) < columns && int(y) < rows) o.cells.push_back(x | (y << 16));
  }
  return o.cells;
}

void CdlodSpriteError::clear() {
  held_.clear();
  recent_.clear();
  recent_next_.clear();
  measure_ = 0;
}

SpriteError CdlodSpriteError::measure(const CdlodTerrain& lod, const GridHeightsFn& heights, uint64_t heights_version,
                                      std::span<const CdlodNode> nodes, const Vec3& v1, const Vec3& v2,
                                      size_t max_quadrants) {
  ++measure_;
  ++counters_.measures;
  const CdlodGrid& hf = lod.grid();
  const int p = lod.patchCells();
  // Per node of level >= 1: its cells inside the grid (columns x rows), and its weight for the sample's allocation.
  struct Stratum {
    const CdlodNode* node;
    int columns, rows;
    double weight;
    Held* held = nullptr;
    Sampling* sample = nullptr;
    size_t first = 0, k = 1;  // its sampled cells: first, first + k, ...
  };
  std::vector<Stratum> strata;
  strata.reserve(nodes.size());
  size_t cells = 0;
  double total_weight = 0.0;
  size_t cursor = 0;  // in recent_: the last measure's nodes, in the order a selection lists them
  recent_next_.clear();  // (a measure that threw left some)
  for (const CdlodNode& n : nodes) {
    if (n.level < 1) continue;
    const int s = lod.spacing(n.level);
    const int columns = std::clamp((hf.width - 1 - n.x * p * s) / s, 0, p);
    const int rows = std::clamp((hf.height - 1 - n.y * p * s) / s, 0, p);
    if (columns == 0 || rows == 0) continue;
    // Its kept cells, with its box, error and cell order: the terrain's arrays of these are megabytes, a cache miss
    // each after the rasterizer's threads ran, where the held node is one. A selection lists its nodes in the same
    // order from frame to frame, and most of them were the last measure's: they are found by walking that measure's
    // list beside this one (a few entries ahead, where nodes split or merged), the next ones asked of memory early;
    // the others through the hash map (a miss for its bucket, then one for the node).
    const Key key{n.level, n.x, n.y};
    Held* found = nullptr;
    for (size_t look = cursor; look < std::min(recent_.size(), cursor + 4); ++look)
      if (recent_[look].key == key) {
        found = recent_[look].held;
        cursor = look + 1;
        if (cursor + 2 < recent_.size()) __builtin_prefetch(recent_[cursor + 2].held);
        break;
      }
    Held& held = found ? *found : held_[key];
    recent_next_.push_back({key, &held});
    const size_t count = size_t(columns) * size_t(rows);
    if (held.count != count) {  // new to the held set (count 0), or its shape changed
      held = Held{};
      held.count = count;
      held.box = lod.nodeBox(n);
      held.error = lod.nodeError(n);
      held.order = &cellOrder(p, columns, rows);
    }
    held.used = measure_;
    // A cell's theta grows with its central vertex's deviation (at most the node's error E(N)) and falls with the
    // square of its distance from the eye.
    const Vec3 nearest = glm::clamp(v2, held.box.lo, held.box.hi);
    const double d = std::max(double(glm::length(v2 - nearest)), 1.0);
    const double w = double(held.error) / (d * d);
    strata.push_back({&n, columns, rows, w * w, &held});
    cells += count;
    total_weight += w * w;
  }
  // A cell's five grid points: its corners, then its centre.
  auto cellPoint = [&](const Stratum& st, size_t c, int corner) {
    const int s = lod.spacing(st.node->level);
    const uint32_t ij = (*st.held->order)[c];
    const int cx = st.node->x * p * s + int(ij & 0xFFFFu) * s;
    const int cy = st.node->y * p * s + int(ij >> 16) * s;
    constexpr int dx[5] = {0, 2, 2, 0, 1}, dy[5] = {0, 0, 2, 2, 1};
    return IVec2(cx + dx[corner] * s / 2, cy + dy[corner] * s / 2);
  };
  // The sample: per stratum every k-th cell in the patch's Morton order, from an offset fixed by the node, k a power
  // of two: each such sample is a regular subgrid of the node's cells (every other column, then every other row
  // too, ...), and the samples of a node nest, so that a node whose share halves keeps every cell it had, and one
  // whose share doubles finds half of its cells held (odd strides over rows, which changed with every few per cent
  // of a share, turned all of a node's sampled cells over: 10-30 nodes a measure on the 16,385^2 flight, where a share
  // goes as d^-4 and the eye moves 465 m a frame). k is the largest power of two up to 1.75 times the stride that
  // would take the node's share of the cells, so that it takes between 4/7 and 8/7 of its share: on the flight about
  // the size of sample the odd strides took (890 cells a measure for 840, of 1,024 asked). The cells a node never had
  // are asked for at once.
  for (Stratum& st : strata) {
    const CdlodNode& n = *st.node;
    const size_t count = st.held->count;
    if (max_quadrants > 0 && cells > max_quadrants) {
      const double share = total_weight > 0.0 ? st.weight / total_weight : 1.0 / double(strata.size());
      const double taken = std::clamp(share * double(max_quadrants), 1.0, double(count));
      st.k = std::bit_floor(std::min(count, std::max<size_t>(1, size_t(1.75 * double(count) / taken))));
    }
    uint32_t h = uint32_t(n.x) * 0x9E3779B1u ^ uint32_t(n.y) * 0x85EBCA77u ^ uint32_t(n.level) * 0xC2B2AE3Du;
    h ^= h >> 15;
    st.first = st.k > 1 ? size_t(h) % st.k : 0;
    st.sample = &sampling(*st.held, st.first, st.k);
    st.sample->used = measure_;
    __builtin_prefetch(st.sample->cells.data());
  }
  points_.clear();
  asked_.clear();
  for (Stratum& st : strata) {
    Sampling& sample = *st.sample;
    for (size_t j = 0; j < sample.cells.size(); ++j) {
      const size_t c = st.first + j * st.k;
      Cell& cell = sample.cells[j];
      // Heights that stood in are asked for again once the terrain's heights changed (they may have been replaced).
      if (cell.have == 1 || (cell.have == 2 && cell.version == heights_version)) {
        ++counters_.cells_kept;
        continue;
      }
      ++counters_.cells_gathered;
      asked_.push_back(&cell);
      for (int corner = 0; corner < 5; ++corner) points_.push_back(cellPoint(st, c, corner));
    }
  }
  z_.assign(points_.size(), 0.0f);
  own_.assign(points_.size(), uint8_t(1));
  if (!points_.empty()) heights(points_, z_, own_);
  for (size_t a = 0; a < asked_.size(); ++a) {
    Cell& cell = *asked_[a];
    bool own = true;
    for (size_t corner = 0; corner < 5; ++corner) {
      cell.z[corner] = z_[5 * a + corner];
      own = own && own_[5 * a + corner] != 0;
    }
    cell.have = own ? 1 : 2;
    cell.version = heights_version;
    cell.eye = 0;
  }

  SpriteError e;
  const DVec3 eye1(v1), eye2(v2);
  // As Heightfield::position: (i * cell_x, j * cell_y, height).
  auto position = [&](const Stratum& st, size_t c, const Cell& cell, int corner) {
    const IVec2 g = cellPoint(st, c, corner);
    return DVec3(Vec3(float(g.x * hf.cell_x), float(g.y * hf.cell_y), cell.z[corner]));
  };
  DVec3 corners[4];
  double weighted = 0.0, weighted_stretch = 0.0, represented = 0.0;
  for (const Stratum& st : strata) {
    Held& held = *st.held;
    if (held.eye1 != eye1 || held.eye_generation == 0) {
      held.eye1 = eye1;
      held.eye_generation = ++eye_generations_;
    }
    double sum = 0.0, stretch = 0.0;
    size_t used = 0;
    for (size_t j = 0; j < st.sample->cells.size(); ++j) {
      const size_t c = st.first + j * st.k;
      Cell& cell = st.sample->cells[j];
      const DVec3 centre = position(st, c, cell, 4);
      if (cell.eye != held.eye_generation) {
        for (int corner = 0; corner < 4; ++corner) corners[corner] = position(st, c, cell, corner);
        cell.projected = spriteProjection(centre, corners, eye1, cell.c_prime, true) ? 1 : 2;
        cell.eye = held.eye_generation;
      } else {
        ++counters_.projections_kept;
      }
      if (cell.projected == 2) {
        ++e.skipped;
        continue;
      }
      const double theta = spriteTheta(centre, cell.c_prime, eye2);
      sum += theta * theta;
      stretch += spriteMagnification(centre, eye1, eye2);
      e.max_theta = std::max(e.max_theta, theta);
      ++used;
    }
    if (used == 0) continue;
    // The node's mean stands for all its cells.
    const double count = double(st.columns) * double(st.rows);
    weighted += sum / double(used) * count;
    weighted_stretch += stretch / double(used) * count;
    represented += count;
    e.quadrants += used;
  }
  e.mean_theta_sq = represented > 0.0 ? weighted / represented : 0.0;
  e.mean_magnification = represented > 0.0 ? weighted_stretch / represented : 1.0;
  // Nodes that no recent measure sampled are forgotten (the held set follows the path; this measure's are all kept).
  std::erase_if(held_, [this](const auto& entry) { return entry.second.used + kKeepMeasures < measure_; });
  recent_.swap(recent_next_);
  return e;
}

SpriteError spriteError(const CdlodTerrain& lod, std::span<const CdlodNode> nodes, const Vec3& v1, const Vec3& v2,
                        size_t max_quadrants) {
  return spriteError(lod, heightfieldHeights(lod.heightfield()), nodes, v1, v2, max_quadrants);
}

GridHeightsFn heightfieldHeights(const Heightfield& hf) {
  return [&hf](std::span<const IVec2> points, std::span<float> out, std::span<uint8_t> own) {
    for (size_t k = 0; k < points.size(); ++k) out[k] = hf.clampedAt(points[k].x, points[k].y);
    std::fill(own.begin(), own.end(), uint8_t(1));
  };
}

SpriteError spriteError(const CdlodTerrain& lod, const GridHeightsFn& heights, std::span<const CdlodNode> nodes,
                        const Vec3& v1, const Vec3& v2, size_t max_quadrants) {
  CdlodSpriteError sample;
  return sample.measure(lod, heights, 0, nodes, v1, v2, max_quadrants);
}

}  // namespace farfield::terrain
