// Lots: a block cut into building lots around a courtyard (layoutBlock), each lot's footprint cleaned and its
// height, bays, balconies and roof drawn.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

#include "farfield/core/check.h"
#include "farfield/gen/buildings.h"

namespace farfield::gen {

namespace {

// Removes near-duplicate vertices and merges collinear edges of the same kind, keeping walls[i] with edge i.
void cleanLot(Polygon2& p, std::vector<WallKind>& k) {
  bool changed = true;
  while (changed && p.size() >= 3) {
    changed = false;
    for (size_t i = 0; i < p.size() && p.size() >= 3; ++i) {
      const size_t n = p.size();
      const size_t j = (i + 1) % n;
      if (glm::length(p[j] - p[i]) < 0.05f) {
        // Edge i has no length: drop vertex j; edge i takes over edge j's end and kind.
        k[i] = k[j];
        p.erase(p.begin() + std::ptrdiff_t(j));
        k.erase(k.begin() + std::ptrdiff_t(j));
        changed = true;
        break;
      }
    }
    if (changed) continue;
    for (size_t i = 0; i < p.size() && p.size() >= 3; ++i) {
      const size_t n = p.size();
      const size_t prev = (i + n - 1) % n, next = (i + 1) % n;
      const DVec2 a(p[prev]), b(p[i]), c(p[next]);
      const DVec2 ab = b - a, bc = c - b;
      const double area2 = std::abs(cross2(ab, bc));
      const double scale = glm::length(ab) * glm::length(bc);
      const bool collinear = area2 <= 1e-4 * scale;
      const bool spike = collinear && glm::dot(ab, bc) < 0.0;
      if (spike || (collinear && k[prev] == k[i])) {
        // Vertex i goes; edge prev now runs to p[next].
        p.erase(p.begin() + std::ptrdiff_t(i));
        k.erase(k.begin() + std::ptrdiff_t(i));
        changed = true;
        break;
      }
    }
  }
}

struct Strip {
  std::vector<Vec2> dir, inward;
  std::vector<float> len, arc;  // arc[i]: perimeter position of vertex i; arc[n] = perimeter
  std::vector<float> q0, q1;    // inner edge i spans [q0, q1] in edge i's coordinate along dir
  Polygon2 inner;               // ring corner of each vertex (repeats where edges were swallowed)
  Polygon2 courtyard;           // inner without repeats
  float depth = 0.0f;
};

// Inner polygon of the lot ring: every edge's line moved inward by `depth`, consecutive lines intersected. An edge
// whose inner segment comes out reversed (a short edge between two corners that turn the same way, e.g. a chamfer
// at a junction) is swallowed: it is dropped and its neighbours' lines meet directly, as in a straight skeleton;
// its strip becomes a triangle ending in that meeting point. inner[i] is where vertex i's corner of the ring lies
// (the start of inner edge i, the end of inner edge i - 1), so inner edges may have zero length.
// Valid when at least three edges survive, the inner polygon is simple and counter-clockwise, and everything on
// it lies at least ~depth from the block boundary (so that strips of opposite sides do not overlap).
bool buildStrip(const Polygon2& p, float depth, Strip& s) {
  const size_t n = p.size();
  s.dir.resize(n);
  s.inward.resize(n);
  s.len.resize(n);
  s.arc.resize(n + 1);
  s.q0.resize(n);
  s.q1.resize(n);
  s.inner.resize(n);
  s.depth = depth;
  s.arc[0] = 0.0f;
  for (size_t i = 0; i < n; ++i) {
    const Vec2 e = p[(i + 1) % n] - p[i];
    s.len[i] = glm::length(e);
    if (s.len[i] <= 0.0f) return false;
    s.dir[i] = e / s.len[i];
    s.inward[i] = Vec2(-s.dir[i].y, s.dir[i].x);
    s.arc[i + 1] = s.arc[i] + s.len[i];
  }
  // Meeting point of the offset lines of edges a and b (b after a, possibly with swallowed edges between).
  auto meet = [&](size_t a, size_t b, DVec2& out) {
    const DVec2 ta(s.dir[a]), tb(s.dir[b]);
    const DVec2 qa = DVec2(p[a]) + DVec2(s.inward[a]) * double(depth);
    const DVec2 qb = DVec2(p[b]) + DVec2(s.inward[b]) * double(depth);
    const double denom = cross2(ta, tb);
    if (std::abs(denom) < 1e-6) {
      if (glm::dot(ta, tb) < 0.0) return false;  // anti-parallel: the block is thinner than twice the depth
      out = qb;                                  // collinear: the corner of b moved inward
      return true;
    }
    out = qa + ta * (cross2(qb - qa, tb) / denom);
    return true;
  };
  thread_local std::vector<size_t> active;
  thread_local std::vector<DVec2> start;  // start[k]: where active edge k's inner segment begins
  active.resize(n);
  for (size_t i = 0; i < n; ++i) active[i] = i;
  while (true) {
    const size_t m = active.size();
    if (m < 3) return false;
    start.resize(m);
    for (size_t k = 0; k < m; ++k)
      if (!meet(active[(k + m - 1) % m], active[k], start[k])) return false;
    // The most reversed inner segment, measured along its edge's direction.
    double worst = 0.0;
    size_t worst_k = m;
    for (size_t k = 0; k < m; ++k) {
      const double len = glm::dot(start[(k + 1) % m] - start[k], DVec2(s.dir[active[k]]));
      if (len <= 1e-6 && (worst_k == m || len < worst)) worst = len, worst_k = k;
    }
    if (worst_k == m) break;
    active.erase(active.begin() + std::ptrdiff_t(worst_k));
  }
  // Map back: vertex i's ring corner is the start of the first active edge at or after edge i.
  const size_t m = active.size();
  for (size_t k = 0; k < m; ++k) {
    const size_t first = active[(k + m - 1) % m] + 1;  // edges after the previous active edge ...
    for (size_t e = first;; ++e) {                     // ... up to and including active[k]
      s.inner[e % n] = Vec2(start[k]);
      if (e % n == active[k]) break;
    }
  }
  for (size_t i = 0; i < n; ++i) {
    s.q0[i] = glm::dot(s.inner[i] - p[i], s.dir[i]);
    s.q1[i] = glm::dot(s.inner[(i + 1) % n] - p[i], s.dir[i]);
  }
  // The courtyard: ring corners without repeats.
  Polygon2 court;
  court.reserve(n);
  for (const Vec2& v : s.inner)
    if (court.empty() || glm::length(v - court.back()) > 1e-3f) court.push_back(v);
  while (court.size() > 1 && glm::length(court.front() - court.back()) <= 1e-3f) court.pop_back();
  if (court.size() < 3 || signedArea(court) <= 0.0 || !isSimplePolygon(court)) return false;
  const double need = 0.97 * double(depth);
  for (size_t i = 0; i < court.size(); ++i) {
    const Vec2 a = court[i], b = court[(i + 1) % court.size()];
    for (int k = 0; k < 4; ++k) {
      const Vec2 q = a + (b - a) * (float(k) / 4.0f);
      if (!pointInPolygon(q, p) || distanceToBoundary(q, p) < need) return false;
    }
  }
  s.courtyard = std::move(court);
  return true;
}

struct ArcPoint {
  size_t edge;
  float t;  // along the edge
};

ArcPoint locate(const Strip& s, float c) {
  const size_t n = s.len.size();
  const float total = s.arc[n];
  c = std::fmod(c, total);
  if (c < 0.0f) c += total;
  size_t e = size_t(std::upper_bound(s.arc.begin(), s.arc.end(), c) - s.arc.begin());
  e = e == 0 ? 0 : e - 1;
  if (e >= n) e = n - 1;
  return {e, std::clamp(c - s.arc[e], 0.0f, s.len[e])};
}

float heightSample(Rng& rng, const LotOptions& o) {
  const float h = o.height_median * o.height_scale * std::exp(o.height_sigma * rng.normal());
  return std::clamp(h, o.height_min, o.height_max);
}

void finishBuilding(Building& b, Rng& rng, const LotOptions& o) {
  b.floor_height = rng.uniform(3.0f, 3.5f);
  const float h = heightSample(rng, o);
  const int floors = std::max(2, int(std::lround(h / b.floor_height)));
  b.height = float(floors) * b.floor_height;
  b.bay_width = rng.uniform(2.8f, 3.6f);
  b.balconies = rng.uniform() < 0.35f;
  b.top = b.height;
}

bool validFootprint(const Polygon2& p) { return p.size() >= 3 && signedArea(p) >= 12.0 && isSimplePolygon(p); }

}  // namespace

BlockLayout layoutBlock(const Polygon2& block_in, uint64_t seed, const LotOptions& o) {
  BlockLayout layout;
  Polygon2 block = cleanPolygon(block_in, 0.05f);
  if (block.size() < 3 || std::abs(signedArea(block)) < 1.0 || !isSimplePolygon(block)) return layout;
  makeCounterClockwise(block);
  Rng rng(seed);

  const double area = signedArea(block);
  float perimeter = 0.0f;
  for (size_t i = 0; i < block.size(); ++i) perimeter += glm::length(block[(i + 1) % block.size()] - block[i]);

  auto singleBuilding = [&]() {
    Building b;
    b.footprint = block;
    b.walls.assign(block.size(), WallKind::Street);
    finishBuilding(b, rng, o);
    layout.buildings.push_back(std::move(b));
    return layout;
  };
  if (area < o.single_building_area || perimeter < 2.0f * o.lot_width_min) return singleBuilding();

  // The ring of lots: shrink the depth until the inner polygon is valid.
  Strip s;
  bool ok = false;
  const float min_depth = 0.75f * o.lot_depth_min;
  for (float depth = rng.uniform(o.lot_depth_min, o.lot_depth_max); depth >= min_depth; depth *= 0.85f)
    if ((ok = buildStrip(block, depth, s))) break;
  if (!ok) return singleBuilding();
  layout.courtyard = s.courtyard;

  // Cuts along the perimeter, each lot lot_width_min..lot_width_max wide. A cut must be perpendicular to its
  // street: it may not fall in the wedge of a convex corner (before the inner edge starts or after it ends), or
  // the lots there would be slivers; such a cut moves forward to where the next inner edge starts, so the corner
  // lot takes the whole corner (a corner building).
  const size_t n = block.size();
  auto straighten = [&](float c) {
    for (size_t guard = 0; guard <= n; ++guard) {
      const ArcPoint ap = locate(s, c);
      const float lo = std::max(0.0f, s.q0[ap.edge]), hi = std::min(s.len[ap.edge], s.q1[ap.edge]);
      // A straight zone of at least half a metre (a swallowed edge has none).
      if (hi - lo >= 0.5f && ap.t <= hi) return ap.t < lo ? c + (lo - ap.t) : c;
      c += s.len[ap.edge] - ap.t + 1e-3f;  // past the end of this edge: on to the next one
    }
    return c;
  };
  std::vector<float> cuts;
  const float start = straighten(rng.uniform(0.0f, perimeter));
  cuts.push_back(start);
  const float end = start + perimeter;
  float pos = start;
  while (true) {
    const float next = straighten(pos + rng.uniform(o.lot_width_min, o.lot_width_max));
    if (end - next < o.lot_width_min) break;
    cuts.push_back(next);
    pos = next;
  }
  if (cuts.size() < 2) {
    const float half = straighten(start + 0.5f * perimeter);
    cuts.push_back(half < end - 1.0f ? half : start + 0.5f * perimeter);
  }
  cuts.push_back(end);

  auto outerPoint = [&](const ArcPoint& ap) { return block[ap.edge] + s.dir[ap.edge] * ap.t; };
  // The cut's inner end: straight across the strip where the inner edge runs alongside, else its nearer end
  // (a swallowed edge's inner edge is a single point).
  auto innerPoint = [&](const ArcPoint& ap) {
    const size_t e = ap.edge;
    const float span = s.q1[e] - s.q0[e];
    if (span <= 1e-6f) return s.inner[e];
    const float alpha = (std::clamp(ap.t, s.q0[e], s.q1[e]) - s.q0[e]) / span;
    return s.inner[e] + (s.inner[(e + 1) % n] - s.inner[e]) * alpha;
  };
  Polygon2 outer_chain, inner_chain;
  std::vector<size_t> corners;
  for (size_t k = 0; k + 1 < cuts.size(); ++k) {
    const float ca = cuts[k], cb = cuts[k + 1], span = cb - ca;
    const ArcPoint pa = locate(s, ca), pb = locate(s, cb);
    // Block corners strictly inside (ca, cb), in order.
    corners.clear();
    const float ca_mod = s.arc[pa.edge] + pa.t;
    for (size_t m = 1; m <= n; ++m) {
      const size_t j = (pa.edge + m) % n;
      float d = s.arc[j] - ca_mod;
      if (d < 0.0f) d += perimeter;
      if (d >= span - 1e-4f) break;
      if (d > 1e-4f) corners.push_back(j);
    }
    Building b;
    b.footprint.clear();
    b.footprint.push_back(outerPoint(pa));
    for (size_t j : corners) b.footprint.push_back(block[j]);
    b.footprint.push_back(outerPoint(pb));
    b.walls.assign(b.footprint.size() - 1, WallKind::Street);
    b.walls.push_back(WallKind::Party);
    b.footprint.push_back(innerPoint(pb));
    for (auto it = corners.rbegin(); it != corners.rend(); ++it) {
      b.footprint.push_back(s.inner[*it]);
      b.walls.push_back(WallKind::Courtyard);
    }
    b.footprint.push_back(innerPoint(pa));
    b.walls.push_back(WallKind::Courtyard);
    b.walls.push_back(WallKind::Party);
    FF_CHECK(b.walls.size() == b.footprint.size());
    cleanLot(b.footprint, b.walls);
    if (!validFootprint(b.footprint)) {
      ++layout.skipped_lots;
      continue;
    }
    finishBuilding(b, rng, o);
    // Pitched roof on a four-sided street lot whose street and courtyard edges are parallel.
    if (b.footprint.size() == 4 && b.height < 30.0f && rng.uniform() < o.gable_share) {
      for (int r = 0; r < 4; ++r) {
        if (b.walls[size_t(r)] != WallKind::Street || b.walls[size_t(r + 2) % 4] != WallKind::Courtyard) continue;
        const Vec2 d0 = glm::normalize(b.footprint[size_t(r + 1) % 4] - b.footprint[size_t(r)]);
        const Vec2 d2 = glm::normalize(b.footprint[size_t(r + 3) % 4] - b.footprint[size_t(r + 2) % 4]);
        if (std::abs(cross2(d0, d2)) > 0.01f || glm::dot(d0, d2) > 0.0f) continue;
        b.roof = RoofShape::Gable;
        b.ridge_edge = r;
        b.roof_rise = 0.5f * s.depth * std::tan(float(degToRad(rng.uniform(28.0f, 42.0f))));
        b.top = b.height + b.roof_rise;
        break;
      }
    }
    layout.buildings.push_back(std::move(b));
  }
  return layout;
}

}  // namespace farfield::gen
