// Street graph: a planar half-edge (winged-edge) graph of junctions and streets whose bounded faces are the city
// blocks (Sillion 1997, section 3: a viewing cell is an oriented street edge; Decoret 1999 reuses it).
//
// Indices:
//   junction j in [0, junctionCount())
//   street s in [0, streetCount()): an undirected segment between two junctions
//   half-edge e in [0, halfEdgeCount()) = 2 * streetCount(): e = 2s runs a -> b of street s, e = 2s + 1 runs
//     b -> a; twin(e) == e ^ 1, street(e) == e / 2. A half-edge is an oriented street edge (a viewing cell).
//   face f in [0, faceCount()): face 0 (kOuterFace) is the unbounded outer face; faces 1.. are the blocks.
// The face of a half-edge lies to its LEFT; next(e) / prev(e) walk that face's boundary counter-clockwise (bounded
// faces) or clockwise (the outer boundary). Curved streets are chains of degree-2 junctions.
//
// A disconnected graph is accepted; every component's outer boundary belongs to the outer face (a component lying
// inside a block of another does not become a hole of that block). Euler's formula V - E + F = 1 + components.
//
// File (`*.streets.json`):
//   {"format": "farfield-streets", "version": 1,
//    "junctions": [[x, y], ...],
//    "streets": [{"a": 0, "b": 1, "width": 12.0, "class": 1}, ...],
//    "faces": [{"outer": true, "junctions": [...]}, ...]}   // derived, written for information, ignored on load
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "farfield/core/bounds.h"
#include "farfield/core/math.h"
#include "farfield/core/polygon2d.h"

namespace farfield::urban {

inline constexpr uint32_t kNone = 0xffffffffu;
inline constexpr uint32_t kOuterFace = 0;

enum StreetClass : int { kAvenue = 0, kStreet = 1, kLane = 2 };

// Input description of one street: an undirected segment between junctions a and b.
struct Street {
  uint32_t a = 0;
  uint32_t b = 0;
  float width = 12.0f;   // metres, kerb to kerb
  int street_class = kStreet;
};

struct HalfEdge {
  uint32_t origin = kNone;
  uint32_t next = kNone;  // next half-edge around face (to the left)
  uint32_t prev = kNone;
  uint32_t face = kNone;
};

struct Face {
  uint32_t edge = kNone;  // one half-edge of its boundary (kNone for the outer face of an empty graph)
  bool outer = false;
};

class StreetGraph {
 public:
  StreetGraph() = default;

  // Builds the half-edge structure: outgoing half-edges are sorted by angle around each junction. Throws
  // farfield::Error prefixed with `source` for: non-finite positions ("junction 3: non-finite position"), street
  // indices out of range, zero-length streets ("street 12: zero length"), non-positive or non-finite widths,
  // duplicated streets, overlapping collinear streets and crossing streets (the graph must be planar: streets meet
  // only at shared junctions). check_planarity = false skips the crossing test (O(E) with a grid, but callers that
  // construct planar graphs by design may skip it).
  static StreetGraph build(std::vector<Vec2> junctions, std::vector<Street> streets,
                           const std::string& source = "street graph", bool check_planarity = true);

  // JSON (see the file comment). fromJson/load throw farfield::Error naming `source`/the file and the element.
  nlohmann::json toJson() const;
  static StreetGraph fromJson(const nlohmann::json& json, const std::string& source);
  static StreetGraph load(const std::string& path);
  void save(const std::string& path) const;

  // Counts. faceCount() includes the outer face; blockCount() == faceCount() - 1.
  size_t junctionCount() const { return positions_.size(); }
  size_t streetCount() const { return streets_.size(); }
  size_t halfEdgeCount() const { return edges_.size(); }
  size_t faceCount() const { return faces_.size(); }
  size_t blockCount() const { return faces_.empty() ? 0 : faces_.size() - 1; }
  size_t componentCount() const { return components_; }

  // Raw data.
  const std::vector<Vec2>& junctions() const { return positions_; }
  const std::vector<Street>& streets() const { return streets_; }
  const std::vector<HalfEdge>& halfEdges() const { return edges_; }
  const std::vector<Face>& faces() const { return faces_; }

  // Navigation.
  const Vec2& position(uint32_t junction) const { return positions_[junction]; }
  static uint32_t twin(uint32_t e) { return e ^ 1u; }
  static uint32_t streetOf(uint32_t e) { return e >> 1; }
  uint32_t origin(uint32_t e) const { return edges_[e].origin; }
  uint32_t destination(uint32_t e) const { return edges_[e ^ 1u].origin; }
  uint32_t next(uint32_t e) const { return edges_[e].next; }
  uint32_t prev(uint32_t e) const { return edges_[e].prev; }
  uint32_t face(uint32_t e) const { return edges_[e].face; }
  const Street& street(uint32_t e) const { return streets_[e >> 1]; }
  float width(uint32_t e) const { return streets_[e >> 1].width; }
  int streetClass(uint32_t e) const { return streets_[e >> 1].street_class; }
  bool isOuter(uint32_t face) const { return faces_[face].outer; }
  uint32_t outerFace() const { return kOuterFace; }

  Vec2 originPosition(uint32_t e) const { return positions_[origin(e)]; }
  Vec2 destinationPosition(uint32_t e) const { return positions_[destination(e)]; }
  float length(uint32_t e) const;
  Vec2 direction(uint32_t e) const;  // unit vector origin -> destination

  // Half-edges leaving a junction, counter-clockwise by angle (empty for an isolated junction).
  std::vector<uint32_t> outgoing(uint32_t junction) const;
  size_t degree(uint32_t junction) const;

  // Faces. Boundary walks follow next() from faces_[f].edge; for the outer face of a disconnected graph this is one
  // component's outer boundary only.
  std::vector<uint32_t> edgesOfFace(uint32_t face) const;
  std::vector<uint32_t> faceBoundary(uint32_t face) const;  // junction loop (no repeated closing junction)
  Polygon2 facePolygon(uint32_t face) const;                // counter-clockwise for blocks, clockwise for the outer

  // Blocks touching a half-edge: face(e) and face(twin(e)) (once if equal), the outer face left out unless
  // include_outer. The same for all faces around a junction.
  std::vector<uint32_t> blocksOfEdge(uint32_t e, bool include_outer = false) const;
  std::vector<uint32_t> blocksAtJunction(uint32_t junction, bool include_outer = false) const;

  // Distance from p to the centreline segment of half-edge e (its street).
  float distanceToEdge(const Vec2& p, uint32_t e) const;
  // The half-edge nearest to p (distance to its segment) among those whose direction agrees with `heading`
  // (dot > 0); ties within 1 cm go to the best-aligned one. Falls back to the nearest half-edge when none agrees
  // (heading zero or perpendicular to every street). kNone for a graph without streets. Uses a grid index.
  uint32_t nearestOrientedEdge(const Vec2& p, const Vec2& heading) const;
  // The street nearest to p (kNone without streets).
  uint32_t nearestStreet(const Vec2& p) const;

  Box2 bounds() const;

 private:
  std::vector<Vec2> positions_;
  std::vector<Street> streets_;
  std::vector<HalfEdge> edges_;
  std::vector<Face> faces_;
  std::vector<uint32_t> junction_edge_;  // one outgoing half-edge per junction, kNone if isolated
  size_t components_ = 0;

  // Uniform grid over the street segments for nearest queries.
  Box2 grid_box_;
  float grid_cell_ = 1.0f;
  int grid_nx_ = 0, grid_ny_ = 0;
  std::vector<uint32_t> grid_start_;    // per cell, offset into grid_streets_ (size nx*ny+1)
  std::vector<uint32_t> grid_streets_;  // street ids

  void buildIndex();
  template <class Visit>
  void searchNear(const Vec2& p, Visit&& visit) const;
};

}  // namespace farfield::urban
