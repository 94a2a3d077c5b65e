// Viewing cells of a city (Sillion et al. 1997, section 4.1): a cell is an oriented street edge (a half-edge of the
// street graph). Its local model is the geometry of the blocks touching the street, drawn as geometry; its distant
// model is everything else, replaced by the cell's impostor.
//
// Objects and blocks: each object of the scene is given to the block (bounded face of the street graph) that
// contains the centroid of its 2D footprint (Object::footprint), provided the footprint's bounding box also lies
// within the block's bounding box grown by CellOptions::block_margin. Objects that fail this (no footprint, centroid
// in no block, or a footprint much larger than the block it lands in) are "shared": they belong to every local model
// and to no distant model. In the procedural city this is the ground (object 1): its footprint is the whole city,
// its centroid happens to lie in some central block, and the margin test is what keeps it out of that block. It is
// right to draw it with every cell: it spans the whole city, so no single impostor could stand for it near the
// viewer; it is cheap next to the buildings (two triangles on flat ground, a tessellation of the hill otherwise); and
// with the ground drawn as geometry the distant model is seen "from below" (the undersides of distant ground) far
// less often, which is the case the paper's contour extraction has to work around.
//
// Cell lookup at run time (CellLocator): the oriented street edge the viewer is on and looking along. The paper's
// rule, "the nearest oriented edge whose direction agrees with the view" (StreetGraph::nearestOrientedEdge), picks
// the wrong cell near junctions: a viewer 3 m before a junction, on the right lane of an avenue, is nearer to the
// centreline of the cross street (whose direction agrees with the view by a few degrees) than to the avenue's, and
// gets the cross street's impostor, which looks 90 degrees away from the view (measured on the default city: frames
// at 15 dB PSNR with a quarter of the image missing). The default rule (CellLookup::Street) therefore prefers, among
// the streets the viewer stands on, the one best aligned with the view; see CellLocator.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "farfield/core/bounds.h"
#include "farfield/core/math.h"
#include "farfield/scene/scene.h"
#include "farfield/urban/street_graph.h"

namespace farfield::urban {

// Which blocks form a cell's local model.
enum class LocalModel {
  Edge,      // the blocks touching the street (the faces on either side of the half-edge), the paper's choice
  Junction,  // those plus every block around either end junction (the paper's "pointwise connectivity")
};
// "edge" or "junction"; throws farfield::Error naming `what` for anything else.
LocalModel parseLocalModel(const std::string& text, const std::string& what = "--local");
const char* localModelName(LocalModel model);

// How the viewer's cell is found (see CellLocator).
enum class CellLookup {
  Street,   // the best-aligned edge among those the viewer stands on, else the nearest agreeing edge (default)
  Nearest,  // the nearest edge whose direction agrees with the view (the paper's wording)
};
// "street" or "nearest"; throws farfield::Error naming `what` otherwise.
CellLookup parseCellLookup(const std::string& text, const std::string& what = "cell lookup");
const char* cellLookupName(CellLookup lookup);

// Finds the viewer's cell. With CellLookup::Street, a half-edge e is a candidate when its direction agrees with the
// horizontal view direction h (dot > 0); the viewer stands on e when its ground position p lies within the street's
// half width (at least min_half_width) of the centreline AND between the edge's ends (the projection of p falls on
// the segment, ends included). Among the candidates the viewer stands on, the one with the largest dot(direction, h)
// wins (the nearer one on ties); when the viewer stands on none, the nearest candidate
// (StreetGraph::nearestOrientedEdge). A vertical or zero view direction gives the nearest edge. Keeps its own copy
// of the segments (a uniform grid over them), so it stays valid when moved or copied; lookup() takes the graph it
// was made from for the fallback.
class CellLocator {
 public:
  CellLocator() = default;
  CellLocator(const StreetGraph& graph, CellLookup mode = CellLookup::Street, float min_half_width = 3.0f);
  CellLookup mode() const { return mode_; }
  uint32_t lookup(const StreetGraph& graph, const Vec3& position, const Vec3& view_direction) const;

 private:
  struct Segment {
    Vec2 a, b;
    float half_width = 0.0f;
  };
  CellLookup mode_ = CellLookup::Street;
  std::vector<Segment> streets_;
  Box2 box_;
  float cell_ = 1.0f;
  int nx_ = 0, ny_ = 0;
  std::vector<uint32_t> start_;  // per grid cell, offset into items_ (nx * ny + 1)
  std::vector<uint32_t> items_;  // street ids whose segment grown by its half width overlaps the grid cell
};

struct CellOptions {
  LocalModel local = LocalModel::Edge;
  CellLookup lookup = CellLookup::Street;
  // How far (metres) an object's footprint bounds may reach beyond the bounds of the block holding its centroid and
  // still belong to that block (see the file comment).
  float block_margin = 5.0f;
  // Half-edges shorter than this (metres) are degenerate cells: no creation camera can look along them. They are
  // reported (CellMap::degenerateCells), not baked.
  float min_cell_length = 0.01f;
};

// Objects by block. Object ids are 1-based (scene::Object::id).
struct BlockAssignment {
  std::vector<uint32_t> object_face;                // per object (index id - 1): its face, or kNone when shared
  std::vector<std::vector<uint32_t>> face_objects;  // per face: the ids of its objects, ascending
  std::vector<uint32_t> shared;                     // ids of the shared objects (in every local model), ascending
  size_t without_footprint = 0;                     // shared because they have no footprint
  size_t outside_blocks = 0;                        // shared because their centroid lies in no block
  size_t too_large = 0;                             // shared because their footprint exceeds their block
};

// The assignment described in the file comment. Where bounded faces overlap (a separate street network drawn inside
// a block of another), the smallest face containing the centroid wins. Uses a uniform grid over the blocks' bounds.
BlockAssignment assignObjectsToBlocks(const scene::Scene& scene, const StreetGraph& graph,
                                      const CellOptions& options = {});

class CellMap {
 public:
  CellMap() = default;
  // Assigns the scene's objects to the graph's blocks; keeps its own copy of the graph (the scene is not kept).
  CellMap(StreetGraph graph, const scene::Scene& scene, const CellOptions& options = {});

  const StreetGraph& graph() const { return graph_; }
  const CellOptions& options() const { return options_; }
  const BlockAssignment& assignment() const { return assignment_; }
  size_t cellCount() const { return graph_.halfEdgeCount(); }
  size_t objectCount() const { return assignment_.object_face.size(); }

  // Blocks of the cell's local model (faces, ascending; the outer face never). cell < cellCount().
  std::vector<uint32_t> localBlocks(uint32_t cell) const;
  // Object ids of the local model (objects of the local blocks and the shared objects), ascending.
  std::vector<uint32_t> localObjects(uint32_t cell) const;
  // Object ids of the distant model: every object not in the local model, ascending.
  std::vector<uint32_t> distantObjects(uint32_t cell) const;

  bool degenerate(uint32_t cell) const { return graph_.length(cell) < options_.min_cell_length; }
  std::vector<uint32_t> degenerateCells() const;

  // The cell of a viewer at `position` looking along `view_direction` (only x, y of both are used), by
  // options().lookup (see CellLocator). kNone for a graph without streets.
  uint32_t lookup(const Vec3& position, const Vec3& view_direction) const;

 private:
  StreetGraph graph_;
  CellOptions options_;
  BlockAssignment assignment_;
  CellLocator locator_;
};

}  // namespace farfield::urban
