// Quadtree continuous LOD (Lindstrom et al. 1996, as used by Chen et al. 1999 section 2.2), as longest-edge
// bisection with nested vertex errors and bounding spheres (see quadtree_lod.h for the contract).
#include "farfield/terrain/quadtree_lod.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "farfield/core/check.h"
#include "farfield/core/error.h"

namespace farfield::terrain {
namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();

int lowbit(int v, int block) { return v == 0 ? block : std::min(v & -v, block); }

struct Point {
  int x, y;
};

// The (up to two) triangles of a vertex's diamond, the diamond's parents and children.
struct Diamond {
  LodVertexKind kind = LodVertexKind::BlockCorner;
  int scale = 0;
  Point tri[2][3];
  int tri_count = 0;
  Point parent[2];
  int parent_count = 0;
};

Diamond diamondOf(int x, int y, int block, int w, int h) {
  Diamond d;
  d.kind = lodVertexKind(x, y, block, &d.scale);
  const int half = d.scale / 2;
  auto inside = [&](Point p) { return p.x >= 0 && p.y >= 0 && p.x < w && p.y < h; };
  switch (d.kind) {
    case LodVertexKind::BlockCorner:
      break;
    case LodVertexKind::SquareCentre: {
      // The diagonal runs from the parent square's centre to the corner this square shares with it (main diagonal
      // for block squares, as the refinement starts).
      int sx = 1, sy = 1;
      if (d.scale < block) {
        sx = (x % (2 * d.scale)) == half ? -1 : 1;
        sy = (y % (2 * d.scale)) == half ? -1 : 1;
      }
      const Point d1{x - sx * half, y - sy * half}, d2{x + sx * half, y + sy * half};
      const Point o1{x + sx * half, y - sy * half}, o2{x - sx * half, y + sy * half};
      d.tri[0][0] = o1, d.tri[0][1] = d1, d.tri[0][2] = d2;
      d.tri[1][0] = o2, d.tri[1][1] = d1, d.tri[1][2] = d2;
      d.tri_count = 2;
      if (d.scale < block) {
        d.parent[0] = o1;
        d.parent[1] = o2;
        d.parent_count = 2;
      }
      break;
    }
    case LodVertexKind::EdgeHorizontal:
    case LodVertexKind::EdgeVertical: {
      const bool horizontal = d.kind == LodVertexKind::EdgeHorizontal;
      const Point a = horizontal ? Point{x - half, y} : Point{x, y - half};
      const Point b = horizontal ? Point{x + half, y} : Point{x, y + half};
      const Point apex[2] = {horizontal ? Point{x, y + half} : Point{x + half, y},
                             horizontal ? Point{x, y - half} : Point{x - half, y}};
      for (const Point& c : apex)
        if (inside(c)) {
          d.tri[d.tri_count][0] = c, d.tri[d.tri_count][1] = a, d.tri[d.tri_count][2] = b;
          ++d.tri_count;
          d.parent[d.parent_count++] = c;
        }
      break;
    }
  }
  return d;
}

}  // namespace

LodVertexKind lodVertexKind(int x, int y, int block, int* scale) {
  const int bx = lowbit(x, block), by = lowbit(y, block);
  LodVertexKind kind;
  int s;
  if (bx == by) {
    kind = bx == block ? LodVertexKind::BlockCorner : LodVertexKind::SquareCentre;
    s = bx == block ? block : 2 * bx;
  } else if (bx < by) {
    kind = LodVertexKind::EdgeHorizontal;  // x is an edge midpoint, y lies on a grid line of the scale
    s = 2 * bx;
  } else {
    kind = LodVertexKind::EdgeVertical;
    s = 2 * by;
  }
  if (scale) *scale = s;
  return kind;
}

QuadtreeLod::QuadtreeLod(const Heightfield& hf, int block, IVec2 origin) : hf_(&hf), origin_(origin) {
  init(block, 1);
  computeErrors();
}

QuadtreeLod::QuadtreeLod(const Heightfield& hf, int block, IVec2 origin, int step, std::vector<float> delta,
                         std::vector<float> radius)
    : hf_(&hf), origin_(origin), delta_(std::move(delta)), radius_(std::move(radius)) {
  if (step < 1 || (step & (step - 1)) != 0)
    throw Error(hf.source, "LOD step " + std::to_string(step) + " is not a power of two");
  if (delta_.size() != hf.size() || radius_.size() != hf.size())
    throw Error(hf.source, "precomputed LOD errors do not match the " + std::to_string(hf.width) + "x" +
                               std::to_string(hf.height) + " grid");
  init(block, step);
}

void QuadtreeLod::init(int block, int step) {
  const Heightfield& hf = *hf_;
  const int w = hf.width, h = hf.height;
  if (w < 3 || h < 3) throw Error(hf.source, "grid too small for the quadtree LOD (need at least 3x3 points)");
  if (block == 0) {
    block = 512;
    while (block > 2 && ((w - 1) % block != 0 || (h - 1) % block != 0)) block /= 2;
  }
  if (block < 2 || (block & (block - 1)) != 0 || (w - 1) % block != 0 || (h - 1) % block != 0)
    throw Error(hf.source, std::to_string(w) + "x" + std::to_string(h) +
                               " grid is not made of whole LOD blocks of " + std::to_string(block) +
                               " cells (need (a * block + 1) x (b * block + 1) points; crop with cropForBlocks)");
  block_ = block;
  step_ = step;
  // The full grid's cell: exact, step being a power of two.
  const double cell_x = hf.cell_x / step, cell_y = hf.cell_y / step;
  positions_.resize(hf.size());
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i)
      positions_[hf.index(i, j)] = Vec3(float((i * step + origin_.x) * cell_x),
                                        float((j * step + origin_.y) * cell_y), hf.at(i, j));
}

size_t QuadtreeLod::bytes() const {
  return positions_.capacity() * sizeof(Vec3) + delta_.capacity() * sizeof(float) +
         radius_.capacity() * sizeof(float);
}

int QuadtreeLod::parents(uint32_t v, std::array<uint32_t, 2>& out) const {
  const int w = hf_->width;
  const Diamond d = diamondOf(int(v % uint32_t(w)), int(v / uint32_t(w)), block_, w, hf_->height);
  for (int k = 0; k < d.parent_count; ++k) out[size_t(k)] = uint32_t(d.parent[k].x + d.parent[k].y * w);
  return d.parent_count;
}

void QuadtreeLod::computeErrors() {
  const int w = hf_->width, h = hf_->height;
  const size_t n = hf_->size();
  delta_.assign(n, 0.0f);
  radius_.assign(n, 0.0f);
  auto idx = [w](Point p) { return size_t(p.x) + size_t(p.y) * size_t(w); };

  // Per vertex: the error and extent of its own diamond against the grid points inside it.
  int levels = 0;
  for (int s = 2; s <= block_; s *= 2) ++levels;
  std::vector<std::vector<uint32_t>> by_level(size_t(2 * levels));  // edges of scale 2, centres of scale 2, ...
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t v = idx({x, y});
      const Diamond d = diamondOf(x, y, block_, w, h);
      if (d.kind == LodVertexKind::BlockCorner) {
        delta_[v] = kInfinity;
        continue;
      }
      const int level = int(std::log2(double(d.scale))) - 1;
      by_level[size_t(2 * level + (d.kind == LodVertexKind::SquareCentre ? 1 : 0))].push_back(uint32_t(v));
      const DVec3 pv(positions_[v]);
      double err = 0.0, rad = 0.0;
      for (int t = 0; t < d.tri_count; ++t) {
        Point a = d.tri[t][0], b = d.tri[t][1], c = d.tri[t][2];
        if (cross2(DVec2(b.x - a.x, b.y - a.y), DVec2(c.x - a.x, c.y - a.y)) < 0) std::swap(b, c);
        const double area2 = cross2(DVec2(b.x - a.x, b.y - a.y), DVec2(c.x - a.x, c.y - a.y));
        const double ha = hf_->heights[idx(a)], hb = hf_->heights[idx(b)], hc = hf_->heights[idx(c)];
        const int x0 = std::min({a.x, b.x, c.x}), x1 = std::max({a.x, b.x, c.x});
        const int y0 = std::min({a.y, b.y, c.y}), y1 = std::max({a.y, b.y, c.y});
        for (int py = y0; py <= y1; ++py)
          for (int px = x0; px <= x1; ++px) {
            const double wa = cross2(DVec2(b.x - px, b.y - py), DVec2(c.x - px, c.y - py));
            const double wb = cross2(DVec2(c.x - px, c.y - py), DVec2(a.x - px, a.y - py));
            const double wc = cross2(DVec2(a.x - px, a.y - py), DVec2(b.x - px, b.y - py));
            if (wa < 0 || wb < 0 || wc < 0) continue;
            const double interpolated = (wa * ha + wb * hb + wc * hc) / area2;
            const size_t p = idx({px, py});
            err = std::max(err, std::abs(double(hf_->heights[p]) - interpolated));
            rad = std::max(rad, glm::length(DVec3(positions_[p]) - pv));
          }
      }
      delta_[v] = float(err);
      radius_[v] = float(rad);
    }

  // Saturation, finest level first: every vertex pushes its error and sphere to the vertices it depends on, so a
  // vertex's values cover all of its descendants before it pushes its own.
  for (const auto& level : by_level)
    for (uint32_t v : level) {
      const Diamond d = diamondOf(int(v % uint32_t(w)), int(v / uint32_t(w)), block_, w, h);
      for (int k = 0; k < d.parent_count; ++k) {
        const size_t p = idx(d.parent[k]);
        if (std::isinf(delta_[p])) continue;  // block corners
        delta_[p] = std::max(delta_[p], delta_[v]);
        const float reach = radius_[v] + glm::length(positions_[p] - positions_[v]);
        radius_[p] = std::max(radius_[p], reach * (1.0f + 1e-6f) + 1e-4f);  // float rounding stays conservative
      }
    }
}

double QuadtreeLod::pixelsPerRadian(const Camera& camera) {
  return double(camera.height) / (2.0 * std::tan(double(camera.fov_y) * 0.5));
}

bool QuadtreeLod::active(uint32_t v, const Vec3& eye, double lambda, float tau) const {
  const float delta = delta_[v];
  if (std::isinf(delta)) return true;
  if (!(delta > 0.0f)) return false;
  const double distance = glm::length(DVec3(eye) - DVec3(positions_[v])) - double(radius_[v]);
  return lambda * double(delta) > double(tau) * distance;
}

struct QuadtreeLod::Build {
  Build(const QuadtreeLod& l, bool split_all, bool cull_frustum)
      : lod(l), w(l.hf_->width), all(split_all), cull(cull_frustum) {}
  const QuadtreeLod& lod;
  const int w;
  const bool all;  // split everything (full resolution)
  const bool cull;
  Frustum frustum;
  Vec3 eye{0.0f};
  double lambda = 0.0;
  float tau = 0.0f;
  std::vector<uint32_t>* indices = nullptr;
  std::vector<uint32_t>* quad_centres = nullptr;
  const LodWindow* window = nullptr;

  uint32_t out(Point p) const {
    if (!window) return uint32_t(p.x + p.y * w);
    return uint32_t(p.x * lod.step_ + lod.origin_.x) + uint32_t(p.y * lod.step_ + lod.origin_.y) * window->global_width;
  }

  // -1: sphere outside the frustum, 1: inside, 0: crossing.
  int classify(uint32_t v) const {
    const Vec3 c = lod.positions_[v];
    const float r = lod.radius_[v];
    int result = 1;
    for (const Vec4& p : frustum.planes) {
      const float s = glm::dot(Vec3(p), c) + p.w;
      if (s < -r) return -1;
      if (s < r) result = 0;
    }
    return result;
  }

  // Triangle (a, b, c), counter-clockwise, right angle at a, hypotenuse b-c. sphere: the vertex whose sphere bounds
  // the triangle (its own split vertex, or its parent's for the finest triangles); inside: already known inside.
  void refine(Point a, Point b, Point c, uint32_t sphere, bool inside) {
    const bool has_split = ((b.x + c.x) & 1) == 0 && ((b.y + c.y) & 1) == 0;
    const Point m{(b.x + c.x) / 2, (b.y + c.y) / 2};
    const uint32_t mi = uint32_t(m.x + m.y * w);
    if (has_split) sphere = mi;
    if (cull && !inside) {
      const int cls = classify(sphere);
      if (cls < 0) return;
      inside = cls > 0;
    }
    if (has_split && (all || lod.active(mi, eye, lambda, tau))) {
      refine(m, c, a, sphere, inside);
      refine(m, a, b, sphere, inside);
      return;
    }
    indices->push_back(out(a));
    indices->push_back(out(b));
    indices->push_back(out(c));
    if (has_split && quad_centres) quad_centres->push_back(mi);
  }

  void run() {
    const int s = lod.block_;
    const int bx0 = window ? window->block_x0 : 0, by0 = window ? window->block_y0 : 0;
    const int bx1 = window ? window->block_x1 : lod.blocksX(), by1 = window ? window->block_y1 : lod.blocksY();
    for (int y0 = by0 * s; y0 < by1 * s; y0 += s)
      for (int x0 = bx0 * s; x0 < bx1 * s; x0 += s) {
        const int x1 = x0 + s, y1 = y0 + s;
        const uint32_t centre = uint32_t((x0 + s / 2) + (y0 + s / 2) * w);
        refine({x1, y0}, {x1, y1}, {x0, y0}, centre, false);
        refine({x0, y1}, {x0, y0}, {x1, y1}, centre, false);
      }
  }
};

void QuadtreeLod::build(const Camera& camera, const LodSettings& settings, LodMesh& out,
                        const LodWindow* window) const {
  out.clear();
  if (window)
    FF_CHECK(window->block_x0 >= 0 && window->block_y0 >= 0 && window->block_x1 <= blocksX() &&
             window->block_y1 <= blocksY() && window->global_width >= uint32_t(origin_.x + width()));
  std::vector<uint32_t> centres;
  Build b(*this, false, settings.cull);
  b.frustum = Frustum::fromMatrix(camera.viewProjection());
  b.eye = camera.eye;
  b.lambda = pixelsPerRadian(camera);
  b.tau = settings.pixel_error;
  b.indices = &out.indices;
  b.quad_centres = settings.collect_quadrants ? &centres : nullptr;
  b.window = window;
  b.run();
  if (!settings.collect_quadrants) return;

  std::sort(centres.begin(), centres.end());
  centres.erase(std::unique(centres.begin(), centres.end()), centres.end());
  const int w = hf_->width, h = hf_->height;
  out.quadrants.reserve(centres.size());
  for (uint32_t v : centres) {
    const int x = int(v % uint32_t(w)), y = int(v / uint32_t(w));
    int scale = 0;
    const LodVertexKind kind = lodVertexKind(x, y, block_, &scale);
    const int half = scale / 2;
    LodQuadrant q;
    q.centre = b.out({x, y});
    q.corner_count = 0;
    auto add = [&](int px, int py) {
      if (px < 0 || py < 0 || px >= w || py >= h) return;
      q.corners[q.corner_count++] = b.out({px, py});
    };
    if (kind == LodVertexKind::SquareCentre) {
      add(x - half, y - half), add(x + half, y - half), add(x + half, y + half), add(x - half, y + half);
    } else if (kind == LodVertexKind::EdgeHorizontal) {
      q.square = 0;
      add(x - half, y), add(x, y - half), add(x + half, y), add(x, y + half);
    } else {
      q.square = 0;
      add(x, y - half), add(x + half, y), add(x, y + half), add(x - half, y);
    }
    out.quadrants.push_back(q);
  }
}

LodMesh QuadtreeLod::build(const Camera& camera, const LodSettings& settings) const {
  LodMesh mesh;
  build(camera, settings, mesh);
  return mesh;
}

std::vector<uint32_t> QuadtreeLod::fullResolutionIndices() const {
  std::vector<uint32_t> indices;
  indices.reserve(size_t(hf_->width - 1) * size_t(hf_->height - 1) * 6);
  Build b(*this, true, false);
  b.indices = &indices;
  b.run();
  return indices;
}

void removeTrianglesInside(LodMesh& mesh, const GridRect& rect, uint32_t grid_width) {
  if (rect.empty()) return;
  auto inside = [&](uint32_t v) { return rect.contains(int(v % grid_width), int(v / grid_width)); };
  size_t kept = 0;
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const uint32_t a = mesh.indices[t], b = mesh.indices[t + 1], c = mesh.indices[t + 2];
    if (inside(a) && inside(b) && inside(c)) continue;
    mesh.indices[kept++] = a, mesh.indices[kept++] = b, mesh.indices[kept++] = c;
  }
  mesh.indices.resize(kept);
}

}  // namespace farfield::terrain
