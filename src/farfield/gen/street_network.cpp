// Procedural street network for the city model of Sillion 1997 (section 3: the street graph segments the city; its
// faces are the blocks) and Decoret 1999 (section 6: walkthroughs of a procedural city).
//
// Construction, on a segment soup that is turned into a half-edge graph between phases:
//   1. an irregular grid: columns and rows of varying spacing, junctions jittered (faces stay convex);
//   2. diagonal avenues: a straight line crossing the grid; every street it crosses is split at the crossing point
//      (moved away from the street's ends so no sliver appears next to a junction) and consecutive crossing points
//      are joined inside the face between them. A chord of a convex face splits it into two convex faces, so the
//      graph stays planar by construction;
//   3. irregularity and block count: streets between two blocks are removed (merging the blocks) and lanes are cut
//      across large blocks (splitting them) until the number of bounded faces equals the request;
//   4. curved streets: some streets become chains of short segments along a bow, checked against the boundary of
//      the two blocks they separate.
// The random source is a std::mt19937_64 mapped to numbers by hand, so the same options give the same network with
// every standard library.
#include "farfield/gen/street_network.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "farfield/core/check.h"
#include "farfield/core/error.h"

namespace farfield::gen {

namespace {

using urban::kNone;
using urban::Street;
using urban::StreetGraph;

constexpr float kAvenueWidthMin = 20.0f;
constexpr float kAvenueWidthMax = 24.0f;
constexpr float kDiagonalWidth = 24.0f;
constexpr float kStreetWidth = 12.0f;
constexpr float kLaneWidth = 8.0f;

enum : uint8_t { kBorder = 1, kDiagonal = 2, kCurved = 4, kLaneFlag = 8 };

class Rng {
 public:
  explicit Rng(uint64_t seed) : engine_(seed ^ 0x9e3779b97f4a7c15ull) {}
  double uniform() { return double(engine_() >> 11) * 0x1.0p-53; }  // [0, 1)
  double range(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  uint64_t below(uint64_t n) { return n == 0 ? 0 : engine_() % n; }
  template <class T>
  void shuffle(std::vector<T>& v) {
    for (size_t i = v.size(); i > 1; --i) std::swap(v[i - 1], v[size_t(below(i))]);
  }

 private:
  std::mt19937_64 engine_;
};

DVec2 d2(const Vec2& v) { return DVec2(v.x, v.y); }
Vec2 f2(const DVec2& v) { return Vec2(float(v.x), float(v.y)); }

double orient(const DVec2& a, const DVec2& b, const DVec2& c) { return cross2(b - a, c - a); }

// The network under construction: junction positions and streets with generator flags.
struct Draft {
  std::vector<Vec2> pos;
  std::vector<Street> streets;
  std::vector<uint8_t> flags;

  uint32_t addJunction(const Vec2& p) {
    pos.push_back(p);
    return uint32_t(pos.size() - 1);
  }
  void addStreet(uint32_t a, uint32_t b, float width, int street_class, uint8_t flag) {
    streets.push_back(Street{a, b, width, street_class});
    flags.push_back(flag);
  }
  // Splits street s at a new junction at p: s keeps (a, m), a new street takes (m, b).
  uint32_t split(uint32_t s, const Vec2& p) {
    uint32_t m = addJunction(p);
    Street tail = streets[s];
    tail.a = m;
    streets[s].b = m;
    streets.push_back(tail);
    flags.push_back(flags[s]);
    return m;
  }
  StreetGraph graph() const { return StreetGraph::build(pos, streets, "generateStreetNetwork", false); }
};

// 1. Irregular grid of cols x rows cells.
void makeGrid(Draft& draft, int cols, int rows, float block, Rng& rng) {
  auto spacing = [&](int n) {
    std::vector<double> at(size_t(n) + 1, 0.0);
    for (int i = 1; i <= n; ++i) at[i] = at[i - 1] + block * rng.range(0.7, 1.3);
    return at;
  };
  const std::vector<double> xs = spacing(cols), ys = spacing(rows);
  // Jitter below 12% of the narrowest spacing keeps every cell a convex quadrilateral.
  const double jitter = 0.12 * 0.7 * block;
  auto id = [&](int i, int k) { return uint32_t(k * (cols + 1) + i); };
  for (int k = 0; k <= rows; ++k)
    for (int i = 0; i <= cols; ++i)
      draft.addJunction(Vec2(float(xs[i] + rng.range(-jitter, jitter)), float(ys[k] + rng.range(-jitter, jitter))));
  // Every few lines is an avenue; each avenue has its own width.
  const int period = 4 + int(rng.below(3));
  const int phase = int(rng.below(uint64_t(period)));
  auto lineClass = [&](int line, int count, float& width) {
    if (line != 0 && line != count && (line % period) == phase) {
      width = float(rng.range(kAvenueWidthMin, kAvenueWidthMax));
      return int(urban::kAvenue);
    }
    width = kStreetWidth;
    return int(urban::kStreet);
  };
  for (int k = 0; k <= rows; ++k) {
    float w;
    int c = lineClass(k, rows, w);
    for (int i = 0; i < cols; ++i)
      draft.addStreet(id(i, k), id(i + 1, k), w, c, (k == 0 || k == rows) ? kBorder : 0);
  }
  for (int i = 0; i <= cols; ++i) {
    float w;
    int c = lineClass(i, cols, w);
    for (int k = 0; k < rows; ++k)
      draft.addStreet(id(i, k), id(i, k + 1), w, c, (i == 0 || i == cols) ? kBorder : 0);
  }
}

// 2. One diagonal avenue; returns false when no suitable line was found.
bool addDiagonal(Draft& draft, int index, float block, Rng& rng) {
  const StreetGraph g = draft.graph();
  const Box2 box = g.bounds();
  const DVec2 lo = d2(box.lo), ext = d2(box.extent());
  const double min_gap = 0.2 * block;  // crossing points stay this far from street ends
  struct Crossing {
    double t;        // along the line
    uint32_t street;
    double s;        // along the street, 0 at a, 1 at b
    uint32_t enter;  // face the line enters
    uint32_t leave;  // face the line leaves
  };
  for (int attempt = 0; attempt < 60; ++attempt) {
    const DVec2 c = lo + ext * DVec2(rng.range(0.3, 0.7), rng.range(0.3, 0.7));
    double angle = degToRad(rng.range(20.0, 70.0));
    if (index % 2 == 1) angle = kPi - angle;
    const DVec2 dir(std::cos(angle), std::sin(angle));
    // The line must pass clear of every junction so each crossing is a proper one.
    bool clear = true;
    for (const Vec2& p : g.junctions())
      if (std::abs(cross2(dir, d2(p) - c)) < 0.05) {
        clear = false;
        break;
      }
    if (!clear) continue;
    std::vector<Crossing> cross;
    for (uint32_t s = 0; s < g.streetCount(); ++s) {
      const DVec2 a = d2(g.position(g.streets()[s].a)), b = d2(g.position(g.streets()[s].b));
      const double da = cross2(dir, a - c), db = cross2(dir, b - c);
      if ((da > 0.0) == (db > 0.0)) continue;
      const double sp = da / (da - db);
      const DVec2 p = a + sp * (b - a);
      const DVec2 left(-(b - a).y, (b - a).x);  // the face of half-edge 2s (a -> b) is on this side
      const bool into_left = glm::dot(dir, left) > 0.0;
      const uint32_t fl = g.face(2 * s), fr = g.face(2 * s + 1);
      cross.push_back({glm::dot(p - c, dir), s, sp, into_left ? fl : fr, into_left ? fr : fl});
    }
    if (cross.size() < 2) continue;
    std::sort(cross.begin(), cross.end(), [](const Crossing& x, const Crossing& y) { return x.t < y.t; });
    bool consistent = true;
    for (size_t k = 0; k + 1 < cross.size(); ++k)
      if (cross[k].enter != cross[k + 1].leave) consistent = false;
    if (!consistent) continue;
    int inner = 0;
    for (size_t k = 0; k + 1 < cross.size(); ++k) inner += g.isOuter(cross[k].enter) ? 0 : 1;
    if (inner < 2) continue;

    std::vector<uint32_t> points(cross.size());
    for (size_t k = 0; k < cross.size(); ++k) {
      const Street st = draft.streets[cross[k].street];
      const DVec2 a = d2(draft.pos[st.a]), b = d2(draft.pos[st.b]);
      const double len = glm::length(b - a);
      const double m = std::min(min_gap / len, 0.5);
      const double sp = std::clamp(cross[k].s, m, 1.0 - m);
      points[k] = draft.split(cross[k].street, f2(a + sp * (b - a)));
    }
    for (size_t k = 0; k + 1 < cross.size(); ++k)
      if (!g.isOuter(cross[k].enter))
        draft.addStreet(points[k], points[k + 1], kDiagonalWidth, urban::kAvenue, kDiagonal);
    return true;
  }
  return false;
}

// 3a. Removes up to `count` streets between two different blocks, at most one per block per call, never leaving a
// junction with fewer than two streets. Returns how many were removed (each removes exactly one face).
int removeStreets(Draft& draft, int count, Rng& rng) {
  if (count <= 0) return 0;
  const StreetGraph g = draft.graph();
  std::vector<uint32_t> degree(g.junctionCount(), 0);
  for (const Street& s : draft.streets) ++degree[s.a], ++degree[s.b];
  std::vector<uint32_t> candidates;
  for (uint32_t s = 0; s < draft.streets.size(); ++s) {
    if (draft.flags[s] & (kBorder | kDiagonal)) continue;
    if (draft.streets[s].street_class == urban::kAvenue) continue;
    const uint32_t f1 = g.face(2 * s), f2 = g.face(2 * s + 1);
    if (f1 == f2 || g.isOuter(f1) || g.isOuter(f2)) continue;
    candidates.push_back(s);
  }
  rng.shuffle(candidates);
  std::vector<uint8_t> used(g.faceCount(), 0), removed(draft.streets.size(), 0);
  int done = 0;
  for (uint32_t s : candidates) {
    if (done >= count) break;
    const Street& st = draft.streets[s];
    const uint32_t f1 = g.face(2 * s), f2 = g.face(2 * s + 1);
    if (used[f1] || used[f2] || degree[st.a] < 3 || degree[st.b] < 3) continue;
    used[f1] = used[f2] = 1;
    --degree[st.a];
    --degree[st.b];
    removed[s] = 1;
    ++done;
  }
  size_t w = 0;
  for (size_t s = 0; s < draft.streets.size(); ++s)
    if (!removed[s]) {
      draft.streets[w] = draft.streets[s];
      draft.flags[w] = draft.flags[s];
      ++w;
    }
  draft.streets.resize(w);
  draft.flags.resize(w);
  return done;
}

// 3b. Cuts up to `count` lanes across large blocks, one per block per call. Each lane joins a point of a block's
// longest side to the opposite side, perpendicular to the first; it is kept only when it lies inside the block and
// leaves both halves a usable size. Returns how many were added (each adds exactly one face).
int addLanes(Draft& draft, int count, float block, Rng& rng) {
  if (count <= 0) return 0;
  const StreetGraph g = draft.graph();
  std::vector<uint32_t> faces;
  for (uint32_t f = 1; f < g.faceCount(); ++f) faces.push_back(f);
  rng.shuffle(faces);
  std::vector<uint8_t> street_used(draft.streets.size(), 0);
  const double min_area = 0.45 * double(block) * block;
  const double end_gap = 0.15 * block;
  int done = 0;
  for (uint32_t f : faces) {
    if (done >= count) break;
    const std::vector<uint32_t> edges = g.edgesOfFace(f);
    const size_t n = edges.size();
    if (n < 4) continue;
    const Polygon2 poly = g.facePolygon(f);
    if (signedArea(poly) < min_area) continue;
    // Longest side.
    size_t i1 = 0;
    for (size_t i = 1; i < n; ++i)
      if (g.length(edges[i]) > g.length(edges[i1])) i1 = i;
    const uint32_t e1 = edges[i1];
    if (street_used[urban::StreetGraph::streetOf(e1)]) continue;
    const DVec2 a1 = d2(g.originPosition(e1)), b1 = d2(g.destinationPosition(e1));
    const double len1 = glm::length(b1 - a1);
    if (len1 < 2.0 * end_gap + 1.0) continue;
    const DVec2 dir1 = (b1 - a1) / len1;
    const DVec2 inward(-dir1.y, dir1.x);
    const double s1 = rng.range(0.35, 0.65);
    const DVec2 m1 = a1 + s1 * (b1 - a1);
    // The side hit by the inward perpendicular from m1, nearest first.
    size_t i2 = n;
    double best_t = 0.0, s2 = 0.0;
    for (size_t i = 0; i < n; ++i) {
      if (i == i1) continue;
      const DVec2 a = d2(g.originPosition(edges[i])), b = d2(g.destinationPosition(edges[i]));
      const double den = cross2(inward, b - a);
      if (std::abs(den) < 1e-9) continue;
      const double t = cross2(a - m1, b - a) / den;        // along the perpendicular
      const double u = cross2(a - m1, inward) / den;       // along the side
      if (t <= 1.0 || u < 0.0 || u > 1.0) continue;
      if (i2 == n || t < best_t) i2 = i, best_t = t, s2 = u;
    }
    if (i2 == n) continue;
    const uint32_t e2 = edges[i2];
    if (street_used[urban::StreetGraph::streetOf(e2)] || urban::StreetGraph::streetOf(e2) == urban::StreetGraph::streetOf(e1))
      continue;
    const DVec2 a2 = d2(g.originPosition(e2)), b2 = d2(g.destinationPosition(e2));
    const double len2 = glm::length(b2 - a2);
    if (s2 * len2 < end_gap || (1.0 - s2) * len2 < end_gap) continue;
    if (best_t < 0.35 * block) continue;
    const DVec2 m2 = a2 + s2 * (b2 - a2);
    // The lane must not touch any other side of the block.
    bool ok = true;
    for (size_t i = 0; i < n && ok; ++i) {
      if (i == i1 || i == i2) continue;
      if (segmentsIntersectD(m1, m2, d2(g.originPosition(edges[i])), d2(g.destinationPosition(edges[i])))) ok = false;
    }
    if (!ok) continue;
    // Both halves big enough: the lane splits the polygon at the two points.
    Polygon2 half1, half2;
    {
      half1.push_back(f2(m1));
      for (size_t k = (i1 + 1) % n;; k = (k + 1) % n) {
        half1.push_back(g.originPosition(edges[k]));
        if (k == i2) break;
      }
      half1.push_back(f2(m2));
      half2.push_back(f2(m2));
      for (size_t k = (i2 + 1) % n;; k = (k + 1) % n) {
        half2.push_back(g.originPosition(edges[k]));
        if (k == i1) break;
      }
      half2.push_back(f2(m1));
    }
    if (signedArea(half1) < 0.2 * block * block || signedArea(half2) < 0.2 * block * block) continue;
    const uint32_t s_1 = urban::StreetGraph::streetOf(e1), s_2 = urban::StreetGraph::streetOf(e2);
    street_used[s_1] = street_used[s_2] = 1;
    const uint32_t j1 = draft.split(s_1, f2(m1));
    const uint32_t j2 = draft.split(s_2, f2(m2));
    draft.addStreet(j1, j2, kLaneWidth, urban::kLane, kLaneFlag);
    ++done;
  }
  return done;
}

// 3c. Diagonal streets across up to `count` four-sided blocks, from a corner to the opposite one, at most one per
// block and none making a junction busier than five streets (these are the five-way junctions of the city).
int cutCorners(Draft& draft, int count, Rng& rng) {
  if (count <= 0) return 0;
  const StreetGraph g = draft.graph();
  std::vector<uint32_t> degree(g.junctionCount(), 0);
  for (const Street& s : draft.streets) ++degree[s.a], ++degree[s.b];
  std::vector<uint32_t> faces;
  for (uint32_t f = 1; f < g.faceCount(); ++f)
    if (g.edgesOfFace(f).size() == 4) faces.push_back(f);
  rng.shuffle(faces);
  int done = 0;
  for (uint32_t f : faces) {
    if (done >= count) break;
    const std::vector<uint32_t> loop = g.faceBoundary(f);
    const size_t k = size_t(rng.below(2));
    const uint32_t a = loop[k], b = loop[k + 2];
    if (degree[a] >= 5 || degree[b] >= 5) continue;
    // A convex quadrilateral's diagonal lies inside it; check convexity (all turns left).
    bool convex = true;
    for (size_t i = 0; i < 4; ++i) {
      const DVec2 p = d2(g.position(loop[i])), q = d2(g.position(loop[(i + 1) % 4])),
                  r = d2(g.position(loop[(i + 2) % 4]));
      if (orient(p, q, r) <= 0.0) convex = false;
    }
    if (!convex) continue;
    ++degree[a];
    ++degree[b];
    draft.addStreet(a, b, kStreetWidth, urban::kStreet, kDiagonal);
    ++done;
  }
  return done;
}

// 4. Curved streets: a share of ordinary streets becomes a bowed chain, at most one per block.
void curveStreets(Draft& draft, float block, Rng& rng) {
  const StreetGraph g = draft.graph();
  std::vector<uint32_t> candidates;
  for (uint32_t s = 0; s < draft.streets.size(); ++s) {
    if (draft.flags[s] & (kBorder | kDiagonal)) continue;
    if (draft.streets[s].street_class == urban::kAvenue) continue;
    if (g.length(2 * s) < 0.6f * block) continue;
    const uint32_t f1 = g.face(2 * s), f2 = g.face(2 * s + 1);
    if (f1 == f2 || g.isOuter(f1) || g.isOuter(f2)) continue;
    candidates.push_back(s);
  }
  rng.shuffle(candidates);
  const size_t wanted = (candidates.size() + 4) / 8;
  std::vector<uint8_t> used(g.faceCount(), 0);
  struct Curve {
    uint32_t street;
    std::vector<Vec2> inner;  // interior chain points from a to b
  };
  std::vector<Curve> curves;
  for (uint32_t s : candidates) {
    if (curves.size() >= wanted) break;
    const uint32_t f1 = g.face(2 * s), f2 = g.face(2 * s + 1);
    if (used[f1] || used[f2]) continue;
    const Street st = draft.streets[s];
    const DVec2 a = d2(draft.pos[st.a]), b = d2(draft.pos[st.b]);
    const double len = glm::length(b - a);
    const DVec2 dir = (b - a) / len, nrm(-dir.y, dir.x);
    const int k = std::clamp(int(std::lround(len / 10.0)), 5, 16);
    const bool s_curve = rng.uniform() < 0.3;
    const double sag = len * rng.range(0.05, 0.1) * (rng.uniform() < 0.5 ? -1.0 : 1.0) * (s_curve ? 0.7 : 1.0);
    std::vector<DVec2> chain{a};
    for (int i = 1; i < k; ++i) {
      const double t = double(i) / k;
      const double bow = s_curve ? std::sin(2.0 * kPi * t) : std::sin(kPi * t);
      chain.push_back(a + t * (b - a) + nrm * (sag * bow));
    }
    chain.push_back(b);
    // Check the chain against the sides of both blocks (other than this street).
    bool ok = true;
    for (uint32_t f : {f1, f2}) {
      for (uint32_t e : g.edgesOfFace(f)) {
        if (urban::StreetGraph::streetOf(e) == s) continue;
        const uint32_t ea = g.origin(e), eb = g.destination(e);
        const DVec2 p = d2(g.position(ea)), q = d2(g.position(eb));
        for (size_t i = 0; i + 1 < chain.size() && ok; ++i) {
          const bool first = i == 0, last = i + 2 == chain.size();
          uint32_t shared = kNone;
          if (first && (ea == st.a || eb == st.a)) shared = st.a;
          if (last && (ea == st.b || eb == st.b)) shared = st.b;
          if (shared != kNone) {
            // Meeting at the shared junction: only the angle between them matters.
            const DVec2 j = d2(g.position(shared));
            const DVec2 u = glm::normalize((first ? chain[1] : chain[i]) - j);
            const DVec2 v = glm::normalize((ea == shared ? q : p) - j);
            if (glm::dot(u, v) > std::cos(degToRad(10.0))) ok = false;
            continue;
          }
          if (segmentsIntersectD(chain[i], chain[i + 1], p, q)) ok = false;
        }
        if (!ok) break;
      }
      if (!ok) break;
    }
    if (!ok) continue;
    used[f1] = used[f2] = 1;
    Curve c{s, {}};
    for (size_t i = 1; i + 1 < chain.size(); ++i) c.inner.push_back(Vec2(float(chain[i].x), float(chain[i].y)));
    curves.push_back(std::move(c));
  }
  for (const Curve& c : curves) {
    const Street st = draft.streets[c.street];
    uint32_t prev = st.a;
    for (size_t i = 0; i < c.inner.size(); ++i) {
      const uint32_t j = draft.addJunction(c.inner[i]);
      if (i == 0) {
        draft.streets[c.street].b = j;
        draft.flags[c.street] |= kCurved;
      } else {
        draft.addStreet(prev, j, st.width, st.street_class, uint8_t(draft.flags[c.street] | kCurved));
      }
      prev = j;
    }
    draft.addStreet(prev, st.b, st.width, st.street_class, uint8_t(draft.flags[c.street] | kCurved));
  }
}

size_t boundedFaces(const Draft& draft) { return draft.graph().blockCount(); }

}  // namespace

urban::StreetGraph generateStreetNetwork(const StreetNetworkOptions& options) {
  constexpr int kMaxBlocks = 1000000;
  if (options.blocks < 1 || options.blocks > kMaxBlocks)
    throw Error("street network options", "blocks must be in [1, " + std::to_string(kMaxBlocks) + "], got " +
                                              std::to_string(options.blocks));
  if (!std::isfinite(options.block_size) || options.block_size < 20.0f || options.block_size > 2000.0f)
    throw Error("street network options", "block_size must be in [20, 2000] metres");
  const int target = options.blocks;
  const float block = options.block_size;
  Rng rng(options.seed);

  int diagonals = 0;
  if (options.diagonal_avenues) diagonals = target < 16 ? 0 : target < 400 ? 1 : target < 10000 ? 2 : 3;
  // Each diagonal splits roughly as many blocks as it crosses (about one grid side).
  const double grid_target = std::max(1.0, target - diagonals * std::sqrt(double(target)));
  const double aspect = rng.range(0.75, 1.33);
  const int cols = std::max(1, int(std::lround(std::sqrt(grid_target * aspect))));
  const int rows = std::max(1, int(std::lround(grid_target / cols)));

  Draft draft;
  makeGrid(draft, cols, rows, block, rng);
  for (int d = 0; d < diagonals; ++d) addDiagonal(draft, d, block, rng);

  // Irregularity (a few merged blocks, lanes across a few large ones, diagonal streets across a few), then the
  // exact block count with more removals or lanes.
  int faces = int(boundedFaces(draft));
  faces -= removeStreets(draft, int(std::lround(0.05 * faces)), rng);
  faces += addLanes(draft, int(std::lround(0.03 * faces)), block, rng);
  if (options.diagonal_avenues) faces += cutCorners(draft, int(std::lround(0.02 * faces)), rng);
  for (int round = 0; round < 64 && faces != target; ++round) {
    int changed = 0;
    if (faces > target) {
      changed = removeStreets(draft, faces - target, rng);
      faces -= changed;
    } else {
      changed = addLanes(draft, target - faces, block, rng);
      faces += changed;
    }
    if (changed == 0) break;
  }
  if (options.curved_streets) curveStreets(draft, block, rng);

  // Centre the city on the origin (float positions keep millimetres over tens of kilometres there).
  Box2 box;
  for (const Vec2& p : draft.pos) box.expand(p);
  const Vec2 centre = box.center();
  for (Vec2& p : draft.pos) p -= centre;

  StreetGraph graph = StreetGraph::build(std::move(draft.pos), std::move(draft.streets), "generateStreetNetwork", true);
  FF_CHECK_MSG(std::abs(double(graph.blockCount()) - target) <= 0.1 * target + 0.5,
               "generated block count not within 10% of the request");
  return graph;
}

Polygon2 buildableFootprint(const urban::StreetGraph& graph, uint32_t face) {
  if (face >= graph.faceCount() || graph.isOuter(face)) return {};
  // The boundary with its half-widths; straight runs of one street width (streets split at a crossing, chains
  // that happen to be straight) are merged so the inset does not meet parallel offset lines.
  Polygon2 poly;
  std::vector<float> dist;
  for (uint32_t e : graph.edgesOfFace(face)) {
    poly.push_back(graph.originPosition(e));
    dist.push_back(0.5f * graph.width(e));
  }
  for (bool changed = true; changed && poly.size() > 3;) {
    changed = false;
    for (size_t i = 0; i < poly.size() && poly.size() > 3; ++i) {
      const size_t n = poly.size(), p = (i + n - 1) % n, q = (i + 1) % n;
      const DVec2 a = d2(poly[p]), b = d2(poly[i]), c = d2(poly[q]);
      const double la = glm::length(b - a), lc = glm::length(c - b);
      const bool repeated = la == 0.0;
      const bool straight = la > 0.0 && lc > 0.0 && std::abs(cross2(b - a, c - b)) <= 1e-6 * la * lc &&
                            glm::dot(b - a, c - b) > 0.0 && dist[p] == dist[i];
      if (!repeated && !straight) continue;
      // Vertex i goes: edge p now runs from poly[p] to poly[q] (for a repeated vertex, edge i takes over).
      if (repeated) dist[p] = dist[i];
      poly.erase(poly.begin() + std::ptrdiff_t(i));
      dist.erase(dist.begin() + std::ptrdiff_t(i));
      changed = true;
      break;
    }
  }
  if (poly.size() < 3 || signedArea(poly) <= 0.0) return {};
  Polygon2 inset = insetPolygon(poly, dist);
  if (inset.size() < 3 || signedArea(inset) <= 0.0) return {};
  return inset;
}

std::vector<BlockFootprint> buildableBlocks(const urban::StreetGraph& graph) {
  std::vector<BlockFootprint> blocks;
  for (uint32_t f = 0; f < graph.faceCount(); ++f) {
    Polygon2 footprint = buildableFootprint(graph, f);
    if (!footprint.empty()) blocks.push_back(BlockFootprint{f, std::move(footprint)});
  }
  return blocks;
}

}  // namespace farfield::gen
