#include "farfield/terrain/cdlod.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "farfield/core/check.h"
#include "farfield/core/error.h"
#include "farfield/terrain/quadtree_lod.h"

namespace farfield::terrain {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

bool isPowerOfTwo(int v) { return v > 0 && (v & (v - 1)) == 0; }

float boxDistance(const Box3& box, const Vec3& p) {
  const Vec3 d = glm::max(glm::max(box.lo - p, p - box.hi), Vec3(0.0f));
  return glm::length(d);
}

}  // namespace

int CdlodTerrain::topLevelFor(const CdlodGrid& grid, const CdlodOptions& options, const std::string& what) {
  if (grid.width < 2 || grid.height < 2)
    throw Error(what, "needs a grid of at least 2 x 2 points, got " + std::to_string(grid.width) + " x " +
                          std::to_string(grid.height));
  if (!isPowerOfTwo(options.patch_cells) || options.patch_cells < 2)
    throw Error(what, "patch size must be a power of two >= 2, got " + std::to_string(options.patch_cells));
  if (!(options.morph_fraction >= 0.0f) || !std::isfinite(options.morph_fraction))
    throw Error(what, "morph fraction must be a finite number >= 0");
  if (options.max_level < 0 || options.max_level > 24)
    throw Error(what, "max_level must be in 0..24, got " + std::to_string(options.max_level));
  // The top level: 2^top divides both cell counts (so that the border is a vertex of every level), and above it a
  // single node would already cover the grid.
  int top = 0;
  while (top < options.max_level) {
    const int s = 1 << (top + 1);
    if ((grid.width - 1) % s != 0 || (grid.height - 1) % s != 0) break;
    if (int64_t(options.patch_cells) * (s / 2) >= int64_t(std::max(grid.width, grid.height) - 1)) break;
    ++top;
  }
  return top;
}

CdlodTerrain::CdlodTerrain(const Heightfield& hf, const CdlodOptions& options)
    : hf_(&hf), grid_{hf.width, hf.height, hf.cell_x, hf.cell_y}, options_(options) {
  if (hf.heights.size() != size_t(std::max(hf.width, 0)) * size_t(std::max(hf.height, 0)))
    throw Error("CDLOD terrain (" + hf.source + ")", "the grid's heights do not match its size");
  top_ = topLevelFor(grid_, options, "CDLOD terrain (" + hf.source + ")");
  layOut();
  computeBoxes();
  computeErrors();
}

size_t CdlodTerrain::nodeCountFor(const CdlodGrid& grid, const CdlodOptions& options) {
  const int top = topLevelFor(grid, options);
  size_t total = 0;
  for (int l = 0; l <= top; ++l) {
    const int64_t cells = int64_t(options.patch_cells) << l;
    total += size_t((grid.width - 1 + cells - 1) / cells) * size_t((grid.height - 1 + cells - 1) / cells);
  }
  return total;
}

void CdlodTerrain::layOut() {
  box_offset_.assign(size_t(top_) + 1, 0);
  size_t total = 0;
  for (int l = 0; l <= top_; ++l) {
    box_offset_[size_t(l)] = total;
    total += size_t(nodesX(l)) * size_t(nodesY(l));
  }
}

void CdlodTerrain::computeLevelErrors() {
  error_.assign(size_t(top_) + 1, 0.0f);
  for (int l = 0; l <= top_; ++l) {
    for (int y = 0; y < nodesY(l); ++y)
      for (int x = 0; x < nodesX(l); ++x) error_[size_t(l)] = std::max(error_[size_t(l)], nodeError({l, x, y}));
    if (l > 0) error_[size_t(l)] = std::max(error_[size_t(l)], error_[size_t(l) - 1]);
  }
}

CdlodTerrain::CdlodTerrain(const CdlodGrid& grid, const CdlodOptions& options, std::vector<Vec2> heights,
                           std::vector<float> errors)
    : grid_(grid), options_(options) {
  top_ = topLevelFor(grid_, options);
  layOut();
  const size_t total = box_offset_.back() + size_t(nodesX(top_)) * size_t(nodesY(top_));
  if (heights.size() != total || errors.size() != total)
    throw Error("CDLOD terrain", "node data for " + std::to_string(heights.size()) + " and " +
                                     std::to_string(errors.size()) + " nodes, the grid has " + std::to_string(total));
  boxes_ = std::move(heights);
  node_error_ = std::move(errors);
  computeLevelErrors();
}

const Heightfield& CdlodTerrain::heightfield() const {
  FF_CHECK_MSG(hf_ != nullptr, "a CDLOD terrain made from node data has no heights");
  return *hf_;
}

int CdlodTerrain::nodesX(int level) const {
  const int64_t cells = int64_t(options_.patch_cells) << level;
  return int((int64_t(grid_.width - 1) + cells - 1) / cells);
}

int CdlodTerrain::nodesY(int level) const {
  const int64_t cells = int64_t(options_.patch_cells) << level;
  return int((int64_t(grid_.height - 1) + cells - 1) / cells);
}

size_t CdlodTerrain::nodeIndex(const CdlodNode& node) const {
  return box_offset_[size_t(node.level)] + size_t(node.x) + size_t(node.y) * size_t(nodesX(node.level));
}

Box3 CdlodTerrain::nodeBox(const CdlodNode& node) const {
  const int64_t cells = int64_t(options_.patch_cells) << node.level;
  const int64_t x0 = node.x * cells, y0 = node.y * cells;
  const int64_t x1 = std::min<int64_t>(x0 + cells, grid_.width - 1), y1 = std::min<int64_t>(y0 + cells, grid_.height - 1);
  const Vec2 h = boxes_[nodeIndex(node)];
  const float cx = float(grid_.cell_x), cy = float(grid_.cell_y);
  Box3 box;
  box.lo = Vec3(float(x0) * cx, float(y0) * cy, h.x);
  box.hi = Vec3(float(x1) * cx, float(y1) * cy, h.y);
  return box;
}

void CdlodTerrain::computeBoxes() {
  const Heightfield& hf = *hf_;
  boxes_.assign(nodeCountFor(grid_, options_), Vec2(kInf, -kInf));
  // Level 0 from the grid (each node's points, its border included), the others from their children.
  const int p = options_.patch_cells;
  for (int y = 0; y < nodesY(0); ++y)
    for (int x = 0; x < nodesX(0); ++x) {
      Vec2& b = boxes_[nodeIndex({0, x, y})];
      for (int j = y * p; j <= std::min((y + 1) * p, hf.height - 1); ++j)
        for (int i = x * p; i <= std::min((x + 1) * p, hf.width - 1); ++i) {
          const float h = hf.at(i, j);
          b.x = std::min(b.x, h);
          b.y = std::max(b.y, h);
        }
    }
  for (int l = 1; l <= top_; ++l)
    for (int y = 0; y < nodesY(l); ++y)
      for (int x = 0; x < nodesX(l); ++x) {
        Vec2& b = boxes_[nodeIndex({l, x, y})];
        for (int c = 0; c < 4; ++c) {
          const CdlodNode child{l - 1, 2 * x + (c & 1), 2 * y + (c >> 1)};
          if (child.x >= nodesX(l - 1) || child.y >= nodesY(l - 1)) continue;
          const Vec2 cb = boxes_[nodeIndex(child)];
          b.x = std::min(b.x, cb.x);
          b.y = std::max(b.y, cb.y);
        }
      }
}

void CdlodTerrain::computeErrors() {
  const Heightfield& hf = *hf_;
  node_error_.assign(boxes_.size(), 0.0f);
  auto h = [&](int i, int j) { return hf.clampedAt(i, j); };
  for (int l = 1; l <= top_; ++l) {
    const int cells = options_.patch_cells << l;
    for (int y = 0; y < nodesY(l); ++y)
      for (int x = 0; x < nodesX(l); ++x)
        node_error_[nodeIndex({l, x, y})] =
            float(levelMeshError(h, x * cells, y * cells, std::min((x + 1) * cells, hf.width - 1),
                                 std::min((y + 1) * cells, hf.height - 1), 1 << l));
  }
  computeLevelErrors();
}

size_t CdlodTerrain::bytes() const {
  return boxes_.size() * sizeof(Vec2) + (error_.size() + node_error_.size()) * sizeof(float) +
         box_offset_.size() * sizeof(size_t);
}

bool CdlodTerrain::updateRanges(const Camera& camera, float pixel_error, CdlodRanges& r) const {
  if (!(pixel_error > 0.0f) || !std::isfinite(pixel_error))
    throw Error("CDLOD terrain", "pixel error must be a positive number, got " + std::to_string(pixel_error));
  const double scale = QuadtreeLod::pixelsPerRadian(camera) / double(pixel_error);
  if (r.scale == scale && r.size() == boxes_.size()) return false;
  r.scale = scale;
  {
    std::lock_guard<std::mutex> lock(range_tables_->mutex);
    auto& tables = range_tables_->tables;
    std::erase_if(tables, [](const auto& t) { return t.second.expired(); });
    for (const auto& [made_for, table] : tables)
      if (made_for == scale) {
        r.table = table.lock();
        if (r.table) return true;
      }
  }
  r.table = makeRanges(scale);
  std::lock_guard<std::mutex> lock(range_tables_->mutex);
  range_tables_->tables.emplace_back(scale, r.table);
  return true;
}

std::shared_ptr<const std::vector<Vec3>> CdlodTerrain::makeRanges(double scale) const {
  auto table = std::make_shared<std::vector<Vec3>>(boxes_.size(), Vec3(0.0f));
  std::vector<Vec3>& node = *table;
  const float m = options_.morph_fraction;
  for (int l = 1; l <= top_; ++l) {
    for (int y = 0; y < nodesY(l); ++y)
      for (int x = 0; x < nodesX(l); ++x) {
        const CdlodNode q{l, x, y};
        float start = float(scale * double(node_error_[nodeIndex(q)]));
        if (l >= 2)
          for (int c = 0; c < 4; ++c) {
            const CdlodNode child{l - 1, 2 * x + (c & 1), 2 * y + (c >> 1)};
            if (child.x >= nodesX(l - 1) || child.y >= nodesY(l - 1)) continue;
            start = std::max(start, node[nodeIndex(child)].z + glm::length(nodeBox(child).extent()));
          }
        node[nodeIndex(q)] = Vec3(start, start + m * std::max(start, 0.5f * glm::length(nodeBox(q).extent())), 0.0f);
      }
    // endD: the largest end over each node's 3 x 3 neighbourhood.
    for (int y = 0; y < nodesY(l); ++y)
      for (int x = 0; x < nodesX(l); ++x) {
        float end = 0.0f;
        for (int ny = std::max(0, y - 1); ny <= std::min(nodesY(l) - 1, y + 1); ++ny)
          for (int nx = std::max(0, x - 1); nx <= std::min(nodesX(l) - 1, x + 1); ++nx)
            end = std::max(end, node[nodeIndex({l, nx, ny})].y);
        node[nodeIndex({l, x, y})].z = end;
      }
  }
  return table;
}

void CdlodTerrain::select(const Camera& camera, float pixel_error, bool cull, CdlodSelection& out) const {
  out.ranges_changed = updateRanges(camera, pixel_error, out.ranges);
  out.nodes.clear();
  out.visited = out.culled = 0;
  const Frustum frustum = Frustum::fromMatrix(camera.viewProjection());
  for (int y = 0; y < nodesY(top_); ++y)
    for (int x = 0; x < nodesX(top_); ++x) selectNode({top_, x, y}, camera.eye, cull ? &frustum : nullptr, out);
}

void CdlodTerrain::selectNode(const CdlodNode& node, const Vec3& eye, const Frustum* frustum,
                              CdlodSelection& out) const {
  ++out.visited;
  const Box3 box = nodeBox(node);
  if (frustum && !frustum->intersects(box)) {
    ++out.culled;
    return;
  }
  if (node.level == 0 || !(boxDistance(box, eye) < out.ranges.node(nodeIndex(node)).z)) {
    out.nodes.push_back(node);
    return;
  }
  const int l = node.level - 1;
  for (int c = 0; c < 4; ++c) {
    const CdlodNode child{l, 2 * node.x + (c & 1), 2 * node.y + (c >> 1)};
    if (child.x < nodesX(l) && child.y < nodesY(l)) selectNode(child, eye, frustum, out);
  }
}

float CdlodTerrain::heightAt(float gx, float gy) const {
  const Heightfield& hf = heightfield();
  gx = std::clamp(gx, 0.0f, float(hf.width - 1));
  gy = std::clamp(gy, 0.0f, float(hf.height - 1));
  const int x0 = std::min(int(std::floor(gx)), hf.width - 1), y0 = std::min(int(std::floor(gy)), hf.height - 1);
  const int x1 = std::min(x0 + 1, hf.width - 1), y1 = std::min(y0 + 1, hf.height - 1);
  const float fx = gx - float(x0), fy = gy - float(y0);
  const float a = hf.at(x0, y0) * (1.0f - fx) + hf.at(x1, y0) * fx;
  const float b = hf.at(x0, y1) * (1.0f - fx) + hf.at(x1, y1) * fx;
  return a * (1.0f - fy) + b * fy;
}

float CdlodTerrain::morphFactor(const CdlodNode& node, int i, int j, const CdlodRanges& ranges,
                                const Vec3& eye) const {
  if (node.level >= top_) return 0.0f;
  const int s = 1 << node.level;
  const int64_t cells = int64_t(options_.patch_cells) << node.level;
  const int gx = int(std::min<int64_t>(node.x * cells + int64_t(i) * s, grid_.width - 1));
  const int gy = int(std::min<int64_t>(node.y * cells + int64_t(j) * s, grid_.height - 1));
  // The range: the largest over the nodes of the next level the vertex lies in (as the shader computes it).
  const int up = node.level + 1, up_cells = options_.patch_cells << up;
  const int hx = std::min(gx / up_cells, nodesX(up) - 1), hy = std::min(gy / up_cells, nodesY(up) - 1);
  const int lx = std::min(gx % up_cells == 0 && gx > 0 ? gx / up_cells - 1 : hx, nodesX(up) - 1);
  const int ly = std::min(gy % up_cells == 0 && gy > 0 ? gy / up_cells - 1 : hy, nodesY(up) - 1);
  Vec2 range(0.0f);
  for (int qy : {ly, hy})
    for (int qx : {lx, hx}) range = glm::max(range, Vec2(ranges.node(nodeIndex({up, qx, qy}))));
  if (!(range.y > range.x)) return 0.0f;
  const Vec3 p(float(gx) * float(grid_.cell_x), float(gy) * float(grid_.cell_y), heightfield().at(gx, gy));
  return std::clamp((glm::length(eye - p) - range.x) / (range.y - range.x), 0.0f, 1.0f);
}

Vec3 CdlodTerrain::vertex(const CdlodNode& node, int i, int j, const CdlodRanges& ranges, const Vec3& eye) const {
  FF_CHECK(i >= 0 && j >= 0 && i <= options_.patch_cells && j <= options_.patch_cells);
  const int s = 1 << node.level;
  const int64_t cells = int64_t(options_.patch_cells) << node.level;
  const float k = morphFactor(node, i, j, ranges, eye);
  float mx = float(node.x * cells + int64_t(i) * s) - ((i & 1) ? float(s) * k : 0.0f);
  float my = float(node.y * cells + int64_t(j) * s) - ((j & 1) ? float(s) * k : 0.0f);
  mx = std::min(mx, float(grid_.width - 1));
  my = std::min(my, float(grid_.height - 1));
  return Vec3(mx * float(grid_.cell_x), my * float(grid_.cell_y), heightAt(mx, my));
}

}  // namespace farfield::terrain
