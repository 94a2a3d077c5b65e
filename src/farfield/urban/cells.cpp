// Segmentation of a city into viewing cells (Sillion et al. 1997, section 4.1): oriented street edges, local model =
// blocks touching the street (optionally all blocks around its end junctions), distant model = the rest.
#include "farfield/urban/cells.h"

#include <algorithm>
#include <cmath>

#include "farfield/core/check.h"
#include "farfield/core/error.h"
#include "farfield/core/polygon2d.h"

namespace farfield::urban {

LocalModel parseLocalModel(const std::string& text, const std::string& what) {
  if (text == "edge") return LocalModel::Edge;
  if (text == "junction") return LocalModel::Junction;
  throw Error(what, "unknown local model '" + text + "' (expected edge or junction)");
}

const char* localModelName(LocalModel model) { return model == LocalModel::Junction ? "junction" : "edge"; }

CellLookup parseCellLookup(const std::string& text, const std::string& what) {
  if (text == "street") return CellLookup::Street;
  if (text == "nearest") return CellLookup::Nearest;
  throw Error(what, "unknown cell lookup '" + text + "' (expected street or nearest)");
}

const char* cellLookupName(CellLookup lookup) { return lookup == CellLookup::Nearest ? "nearest" : "street"; }

// ---------------------------------------------------------------------------------------------------------------
// CellLocator
//
// Why "stands on and best aligned" rather than "nearest": see the header. The projection condition (between the
// edge's ends) makes the choice at a junction follow the viewer's progress: coming up an avenue, the incoming edge
// is "on" until the viewer passes the junction centre, the outgoing one from then on, and a cross street only once
// the viewer has turned into it far enough to be better aligned with it.

CellLocator::CellLocator(const StreetGraph& graph, CellLookup mode, float min_half_width) : mode_(mode) {
  streets_.reserve(graph.streetCount());
  for (uint32_t s = 0; s < graph.streetCount(); ++s) {
    const uint32_t e = 2 * s;
    Segment seg{graph.originPosition(e), graph.destinationPosition(e),
                std::max(0.5f * graph.width(e), min_half_width)};
    streets_.push_back(seg);
    box_.expand(glm::min(seg.a, seg.b) - Vec2(seg.half_width));
    box_.expand(glm::max(seg.a, seg.b) + Vec2(seg.half_width));
  }
  if (streets_.empty()) return;
  const Vec2 extent = glm::max(box_.extent(), Vec2(1.0f));
  cell_ = std::max(1.0f, float(std::sqrt(double(extent.x) * double(extent.y) / double(streets_.size()))));
  nx_ = std::clamp(int(std::ceil(extent.x / cell_)), 1, 4096);
  ny_ = std::clamp(int(std::ceil(extent.y / cell_)), 1, 4096);
  auto cx = [&](float x) { return std::clamp(int((x - box_.lo.x) / cell_), 0, nx_ - 1); };
  auto cy = [&](float y) { return std::clamp(int((y - box_.lo.y) / cell_), 0, ny_ - 1); };
  auto for_cells = [&](const Segment& s, auto&& fn) {
    const Vec2 lo = glm::min(s.a, s.b) - Vec2(s.half_width), hi = glm::max(s.a, s.b) + Vec2(s.half_width);
    for (int y = cy(lo.y); y <= cy(hi.y); ++y)
      for (int x = cx(lo.x); x <= cx(hi.x); ++x) fn(size_t(y) * size_t(nx_) + size_t(x));
  };
  start_.assign(size_t(nx_) * size_t(ny_) + 1, 0);
  for (const Segment& s : streets_) for_cells(s, [&](size_t c) { ++start_[c + 1]; });
  for (size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
  items_.resize(start_.back());
  std::vector<uint32_t> fill(start_.begin(), start_.end() - 1);
  for (uint32_t i = 0; i < streets_.size(); ++i) for_cells(streets_[i], [&](size_t c) { items_[fill[c]++] = i; });
}

uint32_t CellLocator::lookup(const StreetGraph& graph, const Vec3& position, const Vec3& view_direction) const {
  FF_CHECK(graph.streetCount() == streets_.size());
  const Vec2 p(position), h(view_direction);
  if (mode_ == CellLookup::Nearest || streets_.empty() || !(glm::dot(h, h) > 0.0f) || !box_.contains(p))
    return graph.nearestOrientedEdge(p, h);
  const DVec2 hn = glm::normalize(DVec2(h)), dp(p);
  const int x = std::clamp(int((p.x - box_.lo.x) / cell_), 0, nx_ - 1);
  const int y = std::clamp(int((p.y - box_.lo.y) / cell_), 0, ny_ - 1);
  const size_t c = size_t(y) * size_t(nx_) + size_t(x);
  uint32_t best = kNone;
  double best_align = -2.0, best_distance = 0.0;
  for (uint32_t k = start_[c]; k < start_[c + 1]; ++k) {
    const Segment& s = streets_[items_[k]];
    const DVec2 a(s.a), b(s.b), ab = b - a;
    const double len2 = glm::dot(ab, ab);
    if (!(len2 > 0.0)) continue;
    const double t = glm::dot(dp - a, ab) / len2;
    if (t < 0.0 || t > 1.0) continue;  // beyond the ends (in the direction of either half-edge)
    const double distance = std::abs(cross2(ab, dp - a)) / std::sqrt(len2);
    if (distance > double(s.half_width)) continue;
    // The half-edge of this street that agrees with the view.
    const double align = glm::dot(ab, hn) / std::sqrt(len2);
    const uint32_t e = 2 * items_[k] + (align >= 0.0 ? 0u : 1u);
    const double a_abs = std::abs(align);
    if (a_abs == 0.0) continue;  // perpendicular: agrees in neither direction
    if (a_abs > best_align + 1e-9 || (a_abs > best_align - 1e-9 && distance < best_distance)) {
      best = e;
      best_align = a_abs;
      best_distance = distance;
    }
  }
  return best != kNone ? best : graph.nearestOrientedEdge(p, h);
}

namespace {

// Uniform grid over the blocks' bounding boxes: each grid cell lists the faces whose bounds overlap it. Blocks are
// many and small compared with the city, so a point query tests only the few faces around it.
class FaceGrid {
 public:
  FaceGrid(const std::vector<Box2>& face_bounds, const std::vector<uint32_t>& faces) {
    for (uint32_t f : faces) box_.expand(face_bounds[f]);
    if (box_.empty()) return;
    const Vec2 extent = glm::max(box_.extent(), Vec2(1.0f));
    // About two faces per grid cell along each axis.
    const double cells = std::max(1.0, 2.0 * double(faces.size()));
    cell_ = float(std::sqrt(double(extent.x) * double(extent.y) / cells));
    cell_ = std::max(cell_, 1.0f);
    nx_ = std::clamp(int(std::ceil(extent.x / cell_)), 1, 4096);
    ny_ = std::clamp(int(std::ceil(extent.y / cell_)), 1, 4096);
    lists_.resize(size_t(nx_) * size_t(ny_));
    for (uint32_t f : faces) {
      const Box2& b = face_bounds[f];
      const int x0 = cellX(b.lo.x), x1 = cellX(b.hi.x), y0 = cellY(b.lo.y), y1 = cellY(b.hi.y);
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) lists_[size_t(y) * size_t(nx_) + size_t(x)].push_back(f);
    }
  }
  // Faces whose bounds may contain p (empty outside the grid).
  const std::vector<uint32_t>& candidates(const Vec2& p) const {
    static const std::vector<uint32_t> kEmpty;
    if (box_.empty() || !box_.contains(p)) return kEmpty;
    return lists_[size_t(cellY(p.y)) * size_t(nx_) + size_t(cellX(p.x))];
  }

 private:
  int cellX(float x) const { return std::clamp(int((x - box_.lo.x) / cell_), 0, nx_ - 1); }
  int cellY(float y) const { return std::clamp(int((y - box_.lo.y) / cell_), 0, ny_ - 1); }

  Box2 box_;
  float cell_ = 1.0f;
  int nx_ = 0, ny_ = 0;
  std::vector<std::vector<uint32_t>> lists_;
};

}  // namespace

BlockAssignment assignObjectsToBlocks(const scene::Scene& scene, const StreetGraph& graph,
                                      const CellOptions& options) {
  BlockAssignment out;
  out.object_face.assign(scene.objects.size(), kNone);
  out.face_objects.resize(graph.faceCount());

  std::vector<Polygon2> polygons(graph.faceCount());
  std::vector<Box2> bounds(graph.faceCount());
  std::vector<double> areas(graph.faceCount(), 0.0);
  std::vector<uint32_t> blocks;
  for (uint32_t f = 0; f < graph.faceCount(); ++f) {
    if (graph.isOuter(f)) continue;
    polygons[f] = graph.facePolygon(f);
    bounds[f] = polygonBounds(polygons[f]);
    areas[f] = std::abs(signedArea(polygons[f]));
    blocks.push_back(f);
  }
  const FaceGrid grid(bounds, blocks);

  for (size_t i = 0; i < scene.objects.size(); ++i) {
    const scene::Object& object = scene.objects[i];
    const uint32_t id = uint32_t(i + 1);
    if (object.footprint.empty()) {
      ++out.without_footprint;
      out.shared.push_back(id);
      continue;
    }
    const Vec2 centroid = polygonCentroid(object.footprint);
    uint32_t best = kNone;
    for (uint32_t f : grid.candidates(centroid)) {
      if (!bounds[f].contains(centroid) || !pointInPolygon(centroid, polygons[f])) continue;
      if (best == kNone || areas[f] < areas[best]) best = f;
    }
    if (best == kNone) {
      ++out.outside_blocks;
      out.shared.push_back(id);
      continue;
    }
    Box2 allowed = bounds[best];
    allowed.lo -= Vec2(options.block_margin);
    allowed.hi += Vec2(options.block_margin);
    const Box2 footprint = polygonBounds(object.footprint);
    if (!allowed.contains(footprint.lo) || !allowed.contains(footprint.hi)) {
      ++out.too_large;
      out.shared.push_back(id);
      continue;
    }
    out.object_face[i] = best;
    out.face_objects[best].push_back(id);
  }
  return out;
}

CellMap::CellMap(StreetGraph graph, const scene::Scene& scene, const CellOptions& options)
    : graph_(std::move(graph)), options_(options) {
  if (!(options.block_margin >= 0.0f) || !std::isfinite(options.block_margin))
    throw Error("cell options", "block margin must be a finite value >= 0");
  assignment_ = assignObjectsToBlocks(scene, graph_, options_);
  locator_ = CellLocator(graph_, options_.lookup);
}

std::vector<uint32_t> CellMap::localBlocks(uint32_t cell) const {
  std::vector<uint32_t> faces = graph_.blocksOfEdge(cell);
  if (options_.local == LocalModel::Junction) {
    for (uint32_t j : {graph_.origin(cell), graph_.destination(cell)})
      for (uint32_t f : graph_.blocksAtJunction(j)) faces.push_back(f);
  }
  std::sort(faces.begin(), faces.end());
  faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
  return faces;
}

std::vector<uint32_t> CellMap::localObjects(uint32_t cell) const {
  std::vector<uint32_t> ids = assignment_.shared;
  for (uint32_t f : localBlocks(cell))
    ids.insert(ids.end(), assignment_.face_objects[f].begin(), assignment_.face_objects[f].end());
  std::sort(ids.begin(), ids.end());
  return ids;
}

std::vector<uint32_t> CellMap::distantObjects(uint32_t cell) const {
  std::vector<uint8_t> local(objectCount() + 1, 0);
  for (uint32_t id : localObjects(cell)) local[id] = 1;
  std::vector<uint32_t> ids;
  for (uint32_t id = 1; id <= objectCount(); ++id)
    if (!local[id]) ids.push_back(id);
  return ids;
}

std::vector<uint32_t> CellMap::degenerateCells() const {
  std::vector<uint32_t> cells;
  for (uint32_t e = 0; e < cellCount(); ++e)
    if (degenerate(e)) cells.push_back(e);
  return cells;
}

uint32_t CellMap::lookup(const Vec3& position, const Vec3& view_direction) const {
  return locator_.lookup(graph_, position, view_direction);
}

}  // namespace farfield::urban
