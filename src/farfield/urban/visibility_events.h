// Visibility-event weights between objects for a street-segment viewing cell (Decoret et al. 1999, section 4.1).
//
// Objects are block footprints on the ground plane; a viewing cell is a segment [PQ] (a street centreline). The
// weight w_ij of two objects quantifies how far they can move relative to each other in the image while the viewer
// walks along [PQ]: it is 0 when neither object meets the other's critical zone (the convex hull of the object and
// [PQ]), otherwise the largest variation, over M on [PQ], of the angle AMB over pairs of representative points
// (A on object i, B on object j), found with the paper's closed forms (equations 1-5). Everything is 2D (the
// orthogonal projection onto the ground plane, as in the paper), in metres and radians, computed in double.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "farfield/core/math.h"
#include "farfield/core/polygon2d.h"

namespace farfield::urban {

// A viewing cell as the paper's segment [PQ] on the ground plane, metres. p == q (a point cell) is allowed.
struct CellSegment {
  Vec2 p{0.0f};
  Vec2 q{0.0f};
};

// Which of the paper's two configurations (section 4.1) gave the extremal angles, or the degenerate one.
enum class AngleCase {
  General,   // y_B != 1: candidates P, Q and the critical points M1, M2, M3 of equations 3-5 that lie on [PQ]
  Parallel,  // (AB) parallel to (PQ): maximum at P, Q or H (where [AB]'s perpendicular bisector meets (PQ)),
             // minimum at P or Q
  OnCell,    // A or B lies on [PQ] itself: the angle is undefined there; reported as min 0, max pi
  Collinear, // A and B both on the line (PQ), off the segment: the angle is constant (0 or pi)
};

// Extremal viewing angles AMB for M on [PQ]: angles in [0, pi] radians, and a point of [PQ] reaching each.
struct ExtremalAngles {
  double min_angle = 0.0;
  double max_angle = 0.0;
  DVec2 argmin{0.0};
  DVec2 argmax{0.0};
  AngleCase angle_case = AngleCase::General;
  double variation() const { return max_angle - min_angle; }
};

// Closed-form extremal angles of A and B seen from M on [PQ] (equations 1-5 and the parallel case). Inputs must be
// finite (FF_CHECK). A == B gives 0 everywhere (General).
ExtremalAngles extremalAngles(const DVec2& p, const DVec2& q, const DVec2& a, const DVec2& b);

// One object for the weight computation.
struct EventObject {
  Polygon2 footprint;     // at least one vertex (a point or a segment is accepted); any orientation
  bool landmark = false;  // edges touching a landmark are boosted (VisibilityEventOptions::landmark_boost)
};

// Representative points of an object (see visibility_events.cpp for the reasoning).
enum class RepresentativePoints {
  FootprintVertices,  // every footprint vertex (default; conservative for non-convex footprints)
  HullVertices,       // vertices of the footprint's convex hull only (fewer pairs, same angular extents)
};

struct VisibilityEventOptions {
  RepresentativePoints points = RepresentativePoints::FootprintVertices;
  // w_ij is multiplied by this when object i or j is a landmark (once, not squared); >= 1. With a layering
  // threshold T this amounts to T / landmark_boost for a landmark's relations, so landmarks get their own layers
  // sooner (section 4.2: "edge weights can be artificially increased").
  double landmark_boost = 2.0;
};

struct WeightEdge {
  uint32_t to = 0;
  double weight = 0.0;  // > 0, radians (boosted)
};

// The paper's graph G for one cell: a node per object, an edge per pair with a non-zero weight (symmetric).
class EventGraph {
 public:
  EventGraph() = default;
  explicit EventGraph(size_t object_count) : adjacency_(object_count) {}

  size_t objectCount() const { return adjacency_.size(); }
  // w_ij (0 without an edge and for i == j). Indices must be < objectCount() (FF_CHECK).
  double weight(uint32_t i, uint32_t j) const;
  // Edges of object i, sorted by `to`.
  std::span<const WeightEdge> edges(uint32_t i) const { return adjacency_[i]; }
  size_t edgeCount() const { return edge_count_; }  // undirected edges
  double maxWeight() const { return max_weight_; }

  // Adds (or raises to `weight`) the undirected edge i-j; weight <= 0 adds nothing. Keeps edges sorted.
  void setWeight(uint32_t i, uint32_t j, double weight);

  // Statistics of the computation that built the graph.
  size_t object_pairs = 0;  // pairs examined
  size_t zone_pairs = 0;    // pairs where one object meets the other's critical zone
  size_t point_pairs = 0;   // representative point pairs evaluated with the closed forms
  size_t on_cell = 0;       // zone pairs where one footprint meets the cell segment (weight pi: the viewer walks
                            // through that object)

 private:
  std::vector<std::vector<WeightEdge>> adjacency_;
  size_t edge_count_ = 0;
  double max_weight_ = 0.0;
};

// Critical zone of an object: convex hull of its footprint and [PQ] (counter-clockwise).
Polygon2 criticalZone(const Polygon2& footprint, const CellSegment& cell);
// Closed footprint `object` (its boundary and, with >= 3 vertices, its inside) meets the convex polygon `zone`.
bool intersectsConvex(const Polygon2& object, const Polygon2& zone);
// Distance from the footprint (boundary and inside) to the segment [PQ]; 0 when they meet.
double distanceToCell(const Polygon2& footprint, const CellSegment& cell);

// Builds the graph for one cell. A pair related through the critical zones where one footprint meets [PQ] gets
// w = pi (times the landmark boost): such an object belongs to the near geometry, not to a layer. Throws farfield::Error for a non-finite cell end point, an object with an empty
// footprint or a non-finite vertex ("object 12: footprint vertex 3 is not finite"), or landmark_boost < 1.
EventGraph computeEventGraph(std::span<const EventObject> objects, const CellSegment& cell,
                             const VisibilityEventOptions& options = {});

}  // namespace farfield::urban
