// Planarisation of street polylines by iterated snap rounding (Hobby 1999; Guibas and Marimont 1998; iterated as in
// Halperin and Packer 2002): pixels of side `merge_tolerance` holding a street end or a crossing are hot, and every
// street becomes the polyline through the centres of the hot pixels it touches, in the order it meets them. One
// round guarantees that no two results cross properly; an output street may still pass through a hot pixel it does
// not belong to, so the rounds repeat on their own output until nothing changes. Every junction is a pixel centre
// of a fixed grid, the set of hot pixels only grows and is bounded by the data's extent, so the rounds end; a
// street still in contact after max_rounds is dropped and counted (a safety net, not expected).
//
// Exactness: positions live on an integer grid whose step is a power of two with every coordinate below 2^22
// steps. Orientation tests are exact in 64-bit integers, the pixel of a crossing is computed exactly in 128-bit
// integers, and because the junctions are floats whose differences and cross products stay far below 2^53, the
// double-precision tests of urban::StreetGraph::build agree with ours.
#include "farfield/geodata/planarize.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_map>
#include <unordered_set>

#include "farfield/core/error.h"

namespace farfield::geodata {

namespace {

using I128 = __int128;

struct IPoint {
  int64_t x = 0, y = 0;
  bool operator==(const IPoint& o) const { return x == o.x && y == o.y; }
  bool operator<(const IPoint& o) const { return x < o.x || (x == o.x && y < o.y); }
};

int64_t orient(const IPoint& a, const IPoint& b, const IPoint& c) {
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}
int sgn(int64_t v) { return (v > 0) - (v < 0); }
int64_t dot(const IPoint& o, const IPoint& p, const IPoint& q) {
  return (p.x - o.x) * (q.x - o.x) + (p.y - o.y) * (q.y - o.y);
}
bool inBox(const IPoint& a, const IPoint& b, const IPoint& c) {
  return std::min(a.x, b.x) <= c.x && c.x <= std::max(a.x, b.x) && std::min(a.y, b.y) <= c.y &&
         c.y <= std::max(a.y, b.y);
}

// Closed segments touch (the predicate of urban::StreetGraph::build, exact here).
bool segmentsTouch(const IPoint& a, const IPoint& b, const IPoint& c, const IPoint& d) {
  const int o1 = sgn(orient(a, b, c)), o2 = sgn(orient(a, b, d));
  const int o3 = sgn(orient(c, d, a)), o4 = sgn(orient(c, d, b));
  if (o1 != o2 && o3 != o4) return true;
  if (o1 == 0 && inBox(a, b, c)) return true;
  if (o2 == 0 && inBox(a, b, d)) return true;
  if (o3 == 0 && inBox(c, d, a)) return true;
  if (o4 == 0 && inBox(c, d, b)) return true;
  return false;
}

int64_t floorDiv(int64_t a, int64_t b) {  // b > 0
  const int64_t q = a / b;
  return (a % b != 0 && a < 0) ? q - 1 : q;
}
I128 floorDiv128(I128 a, I128 b) {  // b > 0
  const I128 q = a / b;
  return (a % b != 0 && a < 0) ? q - 1 : q;
}

struct Seg {
  IPoint a, b;
  float width = 10.0f;
  int cls = urban::kStreet;
};

uint64_t pixelKey(int64_t kx, int64_t ky) { return (uint64_t(uint32_t(int32_t(kx))) << 32) | uint32_t(int32_t(ky)); }

// Pixels: index k covers [k P - P/2, k P + P/2) on each axis; its centre is k P.
struct Pixels {
  int64_t p = 1;
  int64_t index(int64_t v) const { return floorDiv(2 * v + p, 2 * p); }
  IPoint centreOf(const IPoint& q) const { return IPoint{index(q.x) * p, index(q.y) * p}; }
};

// Dense grid over segment boxes, for candidate pairs.
struct SegGrid {
  int64_t lo_x = 0, lo_y = 0, cell = 1, nx = 0, ny = 0;
  std::vector<uint32_t> start, items;

  int64_t cx(int64_t x) const { return std::clamp<int64_t>((x - lo_x) / cell, 0, nx - 1); }
  int64_t cy(int64_t y) const { return std::clamp<int64_t>((y - lo_y) / cell, 0, ny - 1); }

  void build(const std::vector<Seg>& segs) {
    start.clear();
    items.clear();
    nx = ny = 0;
    if (segs.empty()) return;
    int64_t mnx = INT64_MAX, mny = INT64_MAX, mxx = INT64_MIN, mxy = INT64_MIN;
    double total = 0.0;
    for (const Seg& s : segs) {
      mnx = std::min({mnx, s.a.x, s.b.x});
      mny = std::min({mny, s.a.y, s.b.y});
      mxx = std::max({mxx, s.a.x, s.b.x});
      mxy = std::max({mxy, s.a.y, s.b.y});
      total += std::hypot(double(s.b.x - s.a.x), double(s.b.y - s.a.y));
    }
    lo_x = mnx;
    lo_y = mny;
    const double ex = double(mxx - mnx), ey = double(mxy - mny);
    double c = std::max(total / double(segs.size()), 1.0);
    const double max_cells = 4.0 * double(segs.size()) + 16.0;
    while ((ex / c + 1.0) * (ey / c + 1.0) > max_cells) c *= 1.5;
    cell = std::max<int64_t>(1, int64_t(std::ceil(c)));
    nx = (mxx - mnx) / cell + 1;
    ny = (mxy - mny) / cell + 1;
    std::vector<uint32_t> count(size_t(nx * ny) + 1, 0);
    auto for_cells = [&](const Seg& s, auto&& fn) {
      const int64_t x0 = cx(std::min(s.a.x, s.b.x)), x1 = cx(std::max(s.a.x, s.b.x));
      const int64_t y0 = cy(std::min(s.a.y, s.b.y)), y1 = cy(std::max(s.a.y, s.b.y));
      for (int64_t y = y0; y <= y1; ++y)
        for (int64_t x = x0; x <= x1; ++x) fn(size_t(y * nx + x));
    };
    for (const Seg& s : segs) for_cells(s, [&](size_t k) { ++count[k + 1]; });
    std::partial_sum(count.begin(), count.end(), count.begin());
    start = count;
    items.assign(start.back(), 0);
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    for (uint32_t i = 0; i < segs.size(); ++i) for_cells(segs[i], [&](size_t k) { items[fill[k]++] = i; });
  }

  // Every unordered pair of segments listed in a common cell, once.
  std::vector<std::pair<uint32_t, uint32_t>> pairs() const {
    std::vector<uint64_t> keys;
    for (size_t c = 0; c + 1 < start.size(); ++c)
      for (uint32_t i = start[c]; i < start[c + 1]; ++i)
        for (uint32_t k = i + 1; k < start[c + 1]; ++k) {
          const uint32_t s = std::min(items[i], items[k]), t = std::max(items[i], items[k]);
          if (s != t) keys.push_back((uint64_t(s) << 32) | t);
        }
    std::sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    std::vector<std::pair<uint32_t, uint32_t>> out(keys.size());
    for (size_t i = 0; i < keys.size(); ++i) out[i] = {uint32_t(keys[i] >> 32), uint32_t(keys[i] & 0xffffffffu)};
    return out;
  }
};

// Proper crossing (the segments cross at one point interior to both).
bool properCrossing(const Seg& s, const Seg& t) {
  const int64_t o1 = orient(s.a, s.b, t.a), o2 = orient(s.a, s.b, t.b);
  const int64_t o3 = orient(t.a, t.b, s.a), o4 = orient(t.a, t.b, s.b);
  return sgn(o1) * sgn(o2) < 0 && sgn(o3) * sgn(o4) < 0;
}

// Pixel indices of the crossing point of two properly crossing segments, exactly.
std::pair<int64_t, int64_t> crossingPixel(const Seg& s, const Seg& t, int64_t p) {
  I128 den = I128(s.b.x - s.a.x) * (t.b.y - t.a.y) - I128(s.b.y - s.a.y) * (t.b.x - t.a.x);
  I128 num = I128(t.a.x - s.a.x) * (t.b.y - t.a.y) - I128(t.a.y - s.a.y) * (t.b.x - t.a.x);
  if (den < 0) den = -den, num = -num;
  // x = a + (b - a) num / den; pixel = floor((2 x + P) / (2 P)).
  const I128 xn = I128(s.a.x) * den + I128(s.b.x - s.a.x) * num;
  const I128 yn = I128(s.a.y) * den + I128(s.b.y - s.a.y) * num;
  const I128 two_p_den = I128(2 * p) * den;
  return {int64_t(floorDiv128(2 * xn + I128(p) * den, two_p_den)), int64_t(floorDiv128(2 * yn + I128(p) * den, two_p_den))};
}

// The segment touches the closed square of pixel (kx, ky) (exact: doubled coordinates).
bool touchesPixel(const Seg& s, int64_t kx, int64_t ky, int64_t p) {
  const IPoint a{2 * s.a.x, 2 * s.a.y}, b{2 * s.b.x, 2 * s.b.y};
  const int64_t x0 = 2 * kx * p - p, x1 = 2 * kx * p + p, y0 = 2 * ky * p - p, y1 = 2 * ky * p + p;
  if (std::max(a.x, b.x) < x0 || std::min(a.x, b.x) > x1 || std::max(a.y, b.y) < y0 || std::min(a.y, b.y) > y1)
    return false;
  const int s0 = sgn(orient(a, b, {x0, y0})), s1 = sgn(orient(a, b, {x1, y0}));
  const int s2 = sgn(orient(a, b, {x1, y1})), s3 = sgn(orient(a, b, {x0, y1}));
  return !((s0 > 0 && s1 > 0 && s2 > 0 && s3 > 0) || (s0 < 0 && s1 < 0 && s2 < 0 && s3 < 0));
}

// Parameters along the segment where it enters and leaves the closed square (Liang-Barsky), for ordering.
std::pair<long double, long double> enterExit(const Seg& s, int64_t kx, int64_t ky, int64_t p) {
  long double t0 = 0.0L, t1 = 1.0L;
  const long double d[2] = {(long double)(s.b.x - s.a.x), (long double)(s.b.y - s.a.y)};
  const long double o[2] = {(long double)s.a.x, (long double)s.a.y};
  const long double lo[2] = {(long double)(kx * p) - 0.5L * p, (long double)(ky * p) - 0.5L * p};
  const long double hi[2] = {(long double)(kx * p) + 0.5L * p, (long double)(ky * p) + 0.5L * p};
  for (int k = 0; k < 2; ++k) {
    if (d[k] == 0.0L) continue;
    long double ta = (lo[k] - o[k]) / d[k], tb = (hi[k] - o[k]) / d[k];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return {t0, t1};
}

struct EdgeKey {
  IPoint a, b;  // a < b
  bool operator==(const EdgeKey& o) const { return a == o.a && b == o.b; }
};
struct EdgeHash {
  size_t operator()(const EdgeKey& k) const {
    uint64_t h = uint64_t(k.a.x) * 0x9e3779b97f4a7c15ull;
    h ^= uint64_t(k.a.y) + 0x7f4a7c159e3779b9ull + (h << 6) + (h >> 2);
    h ^= uint64_t(k.b.x) * 0xbf58476d1ce4e5b9ull + (h << 6) + (h >> 2);
    h ^= uint64_t(k.b.y) * 0x94d049bb133111ebull + (h << 6) + (h >> 2);
    return size_t(h);
  }
};

// Merges edges joining the same two points (the wider street and the more important class win), drops loops.
size_t dedupe(std::vector<Seg>& segs) {
  std::vector<Seg> out;
  out.reserve(segs.size());
  std::unordered_map<EdgeKey, uint32_t, EdgeHash> seen;
  seen.reserve(segs.size() * 2);
  size_t dropped = 0;
  for (const Seg& s : segs) {
    if (s.a == s.b) continue;
    const EdgeKey k = s.a < s.b ? EdgeKey{s.a, s.b} : EdgeKey{s.b, s.a};
    auto [it, inserted] = seen.emplace(k, uint32_t(out.size()));
    if (inserted) {
      out.push_back(Seg{k.a, k.b, s.width, s.cls});
    } else {
      Seg& kept = out[it->second];
      kept.width = std::max(kept.width, s.width);
      kept.cls = std::min(kept.cls, s.cls);
      ++dropped;
    }
  }
  segs = std::move(out);
  return dropped;
}

// Two segments meet other than at a shared end (or overlap from one): what StreetGraph::build rejects.
bool badPair(const Seg& s, const Seg& t) {
  const bool aa = s.a == t.a, ab = s.a == t.b, ba = s.b == t.a, bb = s.b == t.b;
  const int shared = aa + ab + ba + bb;
  if (shared >= 2) return true;
  if (shared == 1) {
    const IPoint c = (aa || ab) ? s.a : s.b;
    const IPoint p = (s.a == c) ? s.b : s.a, q = (t.a == c) ? t.b : t.a;
    return orient(c, p, q) == 0 && dot(c, p, q) > 0;
  }
  return segmentsTouch(s.a, s.b, t.a, t.b);
}

}  // namespace

urban::StreetGraph planarizeStreets(const std::vector<StreetPolyline>& polylines, const PlanarizeOptions& options,
                                    PlanarizeStats* stats_out, const std::string& source) {
  if (!(options.merge_tolerance > 0.0) || !std::isfinite(options.merge_tolerance))
    throw Error(source, "merge tolerance must be a positive number of metres");
  PlanarizeStats st;

  // The grid: a power-of-two step with every coordinate below 2^22 steps.
  double max_abs = 1.0;
  for (size_t l = 0; l < polylines.size(); ++l)
    for (const DVec2& p : polylines[l].points) {
      if (!std::isfinite(p.x) || !std::isfinite(p.y))
        throw Error(source, "street " + std::to_string(l) + ": non-finite point");
      max_abs = std::max({max_abs, std::abs(p.x), std::abs(p.y)});
    }
  if (max_abs > 1e9) throw Error(source, "coordinates beyond 10^9 m: not local metres");
  const int exponent = std::max(int(std::ceil(std::log2(max_abs + 2.0 * options.merge_tolerance + 1.0))) - 22, -40);
  const double step = std::ldexp(1.0, exponent);
  Pixels px;
  px.p = std::max<int64_t>(1, std::llround(options.merge_tolerance / step));
  if (px.p > (int64_t(1) << 20)) throw Error(source, "merge tolerance too large for the extent of the streets");
  auto to_grid = [&](const DVec2& p) { return IPoint{std::llround(p.x / step), std::llround(p.y / step)}; };

  std::vector<Seg> segs;
  {
    std::unordered_set<uint64_t> pixels_used;
    std::unordered_set<EdgeKey, EdgeHash> points_seen;  // (point, point) keys of distinct input points
    for (const StreetPolyline& line : polylines) {
      bool have_prev = false;
      IPoint prev;
      for (const DVec2& p : line.points) {
        ++st.input_points;
        const IPoint q = to_grid(p);
        if (points_seen.insert(EdgeKey{q, q}).second &&
            !pixels_used.insert(pixelKey(px.index(q.x), px.index(q.y))).second)
          ++st.merged_points;
        if (have_prev) {
          ++st.input_segments;
          if (px.centreOf(prev) == px.centreOf(q)) ++st.zero_length;
          segs.push_back(Seg{prev, q, line.width, line.street_class});
        }
        prev = q;
        have_prev = true;
      }
    }
  }
  // Exact repeats of an input segment (the same way twice, or overlapping ways) are merged at once.
  st.duplicates = dedupe(segs);

  std::unordered_set<uint64_t> hot;
  bool converged = false;
  for (int round = 0; round < options.max_rounds && !segs.empty(); ++round) {
    st.rounds = size_t(round + 1);
    // Hot pixels: street ends and crossings.
    for (const Seg& s : segs) {
      hot.insert(pixelKey(px.index(s.a.x), px.index(s.a.y)));
      hot.insert(pixelKey(px.index(s.b.x), px.index(s.b.y)));
    }
    {
      SegGrid grid;
      grid.build(segs);
      for (auto [i, j] : grid.pairs()) {
        if (!properCrossing(segs[i], segs[j])) continue;
        const auto [kx, ky] = crossingPixel(segs[i], segs[j], px.p);
        if (hot.insert(pixelKey(kx, ky)).second) ++st.crossings;
      }
    }
    // Hot pixels by bucket of 16 x 16 pixels.
    constexpr int64_t kBucket = 16;
    std::unordered_map<uint64_t, std::vector<std::pair<int64_t, int64_t>>> buckets;
    for (uint64_t key : hot) {
      const int64_t kx = int32_t(uint32_t(key >> 32)), ky = int32_t(uint32_t(key & 0xffffffffu));
      buckets[pixelKey(floorDiv(kx, kBucket), floorDiv(ky, kBucket))].emplace_back(kx, ky);
    }

    // Route every segment through the hot pixels it touches.
    std::vector<Seg> next;
    next.reserve(segs.size() + segs.size() / 8);
    bool changed = false;
    struct Hit {
      long double t0, t1;
      int64_t kx, ky;
    };
    std::vector<Hit> hits;
    for (const Seg& s : segs) {
      const int64_t ax = px.index(s.a.x), ay = px.index(s.a.y), bx = px.index(s.b.x), by = px.index(s.b.y);
      hits.clear();
      auto visit_bucket = [&](int64_t x, int64_t y) {
        auto it = buckets.find(pixelKey(x, y));
        if (it == buckets.end()) return;
        for (const auto& [kx, ky] : it->second) {
          if ((kx == ax && ky == ay) || (kx == bx && ky == by)) continue;
          if (!touchesPixel(s, kx, ky, px.p)) continue;
          const auto [t0, t1] = enterExit(s, kx, ky, px.p);
          hits.push_back(Hit{t0, t1, kx, ky});
        }
      };
      const int64_t bx0 = floorDiv(std::min(ax, bx) - 1, kBucket), bx1 = floorDiv(std::max(ax, bx) + 1, kBucket);
      const int64_t by0 = floorDiv(std::min(ay, by) - 1, kBucket), by1 = floorDiv(std::max(ay, by) + 1, kBucket);
      if ((bx1 - bx0 + 1) * (by1 - by0 + 1) <= 64) {
        for (int64_t y = by0; y <= by1; ++y)
          for (int64_t x = bx0; x <= bx1; ++x) visit_bucket(x, y);
      } else if (const double len = std::hypot(double(bx - ax), double(by - ay)) / double(kBucket);
                 9.0 * (2.0 * len + 2.0) > double(buckets.size())) {
        // A segment longer than there are occupied buckets to visit (kilometres across a sparse or damaged extract):
        // every occupied bucket, each point tested against the segment as above.
        for (const auto& [key, points] : buckets) visit_bucket(int32_t(uint32_t(key >> 32)), int32_t(uint32_t(key & 0xffffffffu)));
      } else {
        // A long diagonal street: only the buckets along it (samples every half bucket, with their neighbours).
        std::vector<uint64_t> along;
        const int64_t samples = int64_t(std::ceil(2.0 * len)) + 1;
        for (int64_t k = 0; k <= samples; ++k) {
          const double t = double(k) / double(samples);
          const int64_t cx = floorDiv(int64_t(std::llround(double(ax) + t * double(bx - ax))), kBucket);
          const int64_t cy = floorDiv(int64_t(std::llround(double(ay) + t * double(by - ay))), kBucket);
          for (int64_t dy = -1; dy <= 1; ++dy)
            for (int64_t dx = -1; dx <= 1; ++dx) along.push_back(pixelKey(cx + dx, cy + dy));
        }
        std::sort(along.begin(), along.end());
        along.erase(std::unique(along.begin(), along.end()), along.end());
        for (uint64_t key : along) visit_bucket(int32_t(uint32_t(key >> 32)), int32_t(uint32_t(key & 0xffffffffu)));
      }
      std::sort(hits.begin(), hits.end(), [](const Hit& u, const Hit& v) {
        if (u.t0 != v.t0) return u.t0 < v.t0;
        if (u.t1 != v.t1) return u.t1 < v.t1;
        return u.kx < v.kx || (u.kx == v.kx && u.ky < v.ky);
      });
      const IPoint start{ax * px.p, ay * px.p}, end{bx * px.p, by * px.p};
      IPoint from = start;
      for (const Hit& h : hits) {
        const IPoint c{h.kx * px.p, h.ky * px.p};
        next.push_back(Seg{from, c, s.width, s.cls});
        from = c;
      }
      next.push_back(Seg{from, end, s.width, s.cls});
      st.snapped_to_junction += hits.size();
      if (!hits.empty() || !(start == s.a) || !(end == s.b)) changed = true;
    }
    dedupe(next);  // routed streets that now run along each other become one
    segs = std::move(next);
    if (!changed) {
      converged = true;
      break;
    }
  }

  // Verification with the predicate of StreetGraph::build; after max_rounds without convergence, one street of
  // every pair still in contact is dropped and counted.
  if (!converged && !segs.empty()) {
    SegGrid grid;
    grid.build(segs);
    std::vector<char> dropped(segs.size(), 0);
    for (auto [i, j] : grid.pairs()) {
      if (dropped[i] || dropped[j]) continue;
      if (badPair(segs[i], segs[j])) {
        dropped[j] = 1;
        ++st.unresolved;
      }
    }
    std::vector<Seg> kept;
    for (size_t s = 0; s < segs.size(); ++s)
      if (!dropped[s]) kept.push_back(segs[s]);
    segs = std::move(kept);
  }

  // Junctions: the distinct pixel centres, as floats (exact: below 2^23 steps of 2^exponent).
  std::unordered_map<EdgeKey, uint32_t, EdgeHash> ids;
  std::vector<Vec2> out_pos;
  std::vector<urban::Street> out_streets;
  out_streets.reserve(segs.size());
  auto id_of = [&](const IPoint& p) {
    auto [it, inserted] = ids.emplace(EdgeKey{p, p}, uint32_t(out_pos.size()));
    if (inserted) out_pos.emplace_back(float(std::ldexp(double(p.x), exponent)), float(std::ldexp(double(p.y), exponent)));
    return it->second;
  };
  for (const Seg& s : segs) out_streets.push_back(urban::Street{id_of(s.a), id_of(s.b), s.width, s.cls});
  if (stats_out) *stats_out = st;
  return urban::StreetGraph::build(std::move(out_pos), std::move(out_streets), source, true);
}

}  // namespace farfield::geodata
