// Street graph as a half-edge structure (Sillion 1997, section 3.1: the city is segmented by its street graph;
// a viewing cell is an oriented street edge and the local model is the set of blocks touching it).
#include "farfield/urban/street_graph.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <numeric>
#include <sstream>
#include <utility>

#include <nlohmann/json.hpp>

#include "farfield/core/polygon2d.h"

#include "farfield/core/check.h"
#include "farfield/core/error.h"

namespace farfield::urban {

namespace {

DVec2 d2(const Vec2& v) { return DVec2(v.x, v.y); }

double orient(const DVec2& a, const DVec2& b, const DVec2& c) { return cross2(b - a, c - a); }

// A point where two touching segments meet: the endpoint lying on the other segment, else the crossing point.
Vec2 contactPoint(const DVec2& a, const DVec2& b, const DVec2& c, const DVec2& d) {
  struct Cand { DVec2 p; double dist; };
  Cand cands[4] = {{a, distancePointSegmentD(a, c, d)}, {b, distancePointSegmentD(b, c, d)},
                   {c, distancePointSegmentD(c, a, b)}, {d, distancePointSegmentD(d, a, b)}};
  Cand best = cands[0];
  for (const Cand& k : cands)
    if (k.dist < best.dist) best = k;
  DVec2 p = best.p;
  const double den = cross2(b - a, d - c);
  if (best.dist > 0.0 && den != 0.0) p = a + (b - a) * (cross2(c - a, d - c) / den);
  return Vec2(float(p.x), float(p.y));
}

std::string fmtPoint(const Vec2& p) {
  char buf[96];
  std::snprintf(buf, sizeof(buf), "(%.2f, %.2f)", double(p.x), double(p.y));
  return buf;
}

// Uniform grid of street ids over the bounding box of the junctions, used by the planarity test and the nearest
// queries. Each street is listed in every cell its bounding box overlaps.
struct SegmentGrid {
  Box2 box;
  float cell = 1.0f;
  int nx = 0, ny = 0;
  std::vector<uint32_t> start;
  std::vector<uint32_t> items;

  void build(const std::vector<Vec2>& pos, const std::vector<Street>& streets) {
    box = Box2();
    for (const Street& s : streets) {
      box.expand(pos[s.a]);
      box.expand(pos[s.b]);
    }
    nx = ny = 0;
    start.clear();
    items.clear();
    if (streets.empty()) return;
    double total = 0.0;
    for (const Street& s : streets) total += glm::length(d2(pos[s.b]) - d2(pos[s.a]));
    Vec2 ext = box.extent();
    // Cells about the mean street length, but no more than ~2 cells per street.
    double c = std::max(total / double(streets.size()), 1e-3);
    double max_cells = 2.0 * double(streets.size()) + 16.0;
    while ((double(ext.x) / c + 1.0) * (double(ext.y) / c + 1.0) > max_cells) c *= 1.5;
    cell = float(c);
    nx = std::max(1, int(std::floor(ext.x / cell)) + 1);
    ny = std::max(1, int(std::floor(ext.y / cell)) + 1);
    std::vector<uint32_t> count(size_t(nx) * ny + 1, 0);
    auto forCells = [&](const Street& s, auto&& fn) {
      Vec2 lo = glm::min(pos[s.a], pos[s.b]), hi = glm::max(pos[s.a], pos[s.b]);
      int x0 = cellX(lo.x), x1 = cellX(hi.x), y0 = cellY(lo.y), y1 = cellY(hi.y);
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) fn(size_t(y) * nx + x);
    };
    for (const Street& s : streets) forCells(s, [&](size_t c) { ++count[c + 1]; });
    std::partial_sum(count.begin(), count.end(), count.begin());
    start = count;
    items.assign(start.back(), 0);
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    for (uint32_t i = 0; i < streets.size(); ++i) forCells(streets[i], [&](size_t c) { items[fill[c]++] = i; });
  }
  int cellX(float x) const { return std::clamp(int(std::floor((x - box.lo.x) / cell)), 0, nx - 1); }
  int cellY(float y) const { return std::clamp(int(std::floor((y - box.lo.y) / cell)), 0, ny - 1); }
};

}  // namespace

StreetGraph StreetGraph::build(std::vector<Vec2> junctions, std::vector<Street> streets, const std::string& source,
                               bool check_planarity) {
  StreetGraph g;
  const size_t nj = junctions.size();
  for (size_t j = 0; j < nj; ++j)
    if (!isFinite(junctions[j])) throw Error(source, "junction " + std::to_string(j) + ": non-finite position");
  if (streets.size() >= size_t(kNone / 2)) throw Error(source, "too many streets");
  for (size_t s = 0; s < streets.size(); ++s) {
    const Street& st = streets[s];
    const std::string where = "street " + std::to_string(s) + ": ";
    if (st.a >= nj || st.b >= nj)
      throw Error(source, where + "junction index " + std::to_string(st.a >= nj ? st.a : st.b) +
                              " out of range (" + std::to_string(nj) + " junctions)");
    if (st.a == st.b || junctions[st.a] == junctions[st.b]) throw Error(source, where + "zero length");
    if (!std::isfinite(st.width) || st.width <= 0.0f)
      throw Error(source, where + "width must be a positive number");
  }
  // Duplicates: the same unordered pair twice.
  {
    std::vector<std::pair<uint64_t, uint32_t>> keys(streets.size());
    for (uint32_t s = 0; s < streets.size(); ++s) {
      uint64_t lo = std::min(streets[s].a, streets[s].b), hi = std::max(streets[s].a, streets[s].b);
      keys[s] = {(lo << 32) | hi, s};
    }
    std::sort(keys.begin(), keys.end());
    for (size_t i = 1; i < keys.size(); ++i)
      if (keys[i].first == keys[i - 1].first)
        throw Error(source, "street " + std::to_string(keys[i].second) + ": duplicates street " +
                                std::to_string(keys[i - 1].second));
  }

  g.positions_ = std::move(junctions);
  g.streets_ = std::move(streets);
  const auto& pos = g.positions_;
  const uint32_t ne = uint32_t(g.streets_.size() * 2);
  g.edges_.assign(ne, HalfEdge{});
  for (uint32_t s = 0; s < g.streets_.size(); ++s) {
    g.edges_[2 * s].origin = g.streets_[s].a;
    g.edges_[2 * s + 1].origin = g.streets_[s].b;
  }

  // Outgoing half-edges of each junction sorted counter-clockwise by angle (CSR layout).
  std::vector<uint32_t> out_start(nj + 1, 0);
  for (uint32_t e = 0; e < ne; ++e) ++out_start[g.edges_[e].origin + 1];
  std::partial_sum(out_start.begin(), out_start.end(), out_start.begin());
  std::vector<uint32_t> out(ne);
  {
    std::vector<uint32_t> fill(out_start.begin(), out_start.end() - 1);
    for (uint32_t e = 0; e < ne; ++e) out[fill[g.edges_[e].origin]++] = e;
  }
  std::vector<double> angle(ne);
  for (uint32_t e = 0; e < ne; ++e) {
    DVec2 d = d2(pos[g.edges_[e ^ 1u].origin]) - d2(pos[g.edges_[e].origin]);
    angle[e] = std::atan2(d.y, d.x);
  }
  std::vector<uint32_t> slot(ne);  // position of each half-edge in its origin's list
  for (size_t j = 0; j < nj; ++j) {
    auto first = out.begin() + out_start[j], last = out.begin() + out_start[j + 1];
    std::sort(first, last, [&](uint32_t x, uint32_t y) { return angle[x] < angle[y] || (angle[x] == angle[y] && x < y); });
    const uint32_t n = out_start[j + 1] - out_start[j];
    for (uint32_t k = 0; k < n; ++k) {
      uint32_t e = out[out_start[j] + k];
      slot[e] = k;
      // Two streets leaving j in the same direction overlap.
      uint32_t f = out[out_start[j] + (k + 1) % n];
      if (n > 1 && f != e) {
        DVec2 c = d2(pos[j]), p = d2(pos[g.edges_[e ^ 1u].origin]), q = d2(pos[g.edges_[f ^ 1u].origin]);
        if (orient(c, p, q) == 0.0 && glm::dot(p - c, q - c) > 0.0)
          throw Error(source, "streets " + std::to_string(e / 2) + " and " + std::to_string(f / 2) +
                                  " overlap (collinear from junction " + std::to_string(j) + ")");
      }
    }
  }
  g.junction_edge_.assign(nj, kNone);
  for (size_t j = 0; j < nj; ++j)
    if (out_start[j + 1] > out_start[j]) g.junction_edge_[j] = out[out_start[j]];

  // next(e) for e = u -> v: the half-edge leaving v just clockwise of twin(e), so the face stays on the left.
  for (uint32_t e = 0; e < ne; ++e) {
    uint32_t t = e ^ 1u;
    uint32_t v = g.edges_[t].origin;
    uint32_t n = out_start[v + 1] - out_start[v];
    uint32_t k = slot[t];
    uint32_t nxt = out[out_start[v] + (k + n - 1) % n];
    g.edges_[e].next = nxt;
    g.edges_[nxt].prev = e;
  }

  // Faces: each boundary cycle with positive area bounds a block; cycles with zero or negative area are outer
  // boundaries of components and all belong to the outer face 0.
  g.faces_.push_back(Face{kNone, true});
  double outer_area = 1.0;
  for (uint32_t e0 = 0; e0 < ne; ++e0) {
    if (g.edges_[e0].face != kNone) continue;
    const DVec2 o = d2(pos[g.edges_[e0].origin]);
    double twice = 0.0;
    uint32_t e = e0;
    size_t guard = 0;
    do {
      DVec2 a = d2(pos[g.edges_[e].origin]) - o, b = d2(pos[g.edges_[e ^ 1u].origin]) - o;
      twice += cross2(a, b);
      e = g.edges_[e].next;
      FF_CHECK(++guard <= ne);
    } while (e != e0);
    uint32_t f = kOuterFace;
    if (twice > 0.0) {
      f = uint32_t(g.faces_.size());
      g.faces_.push_back(Face{e0, false});
    } else if (twice < outer_area) {
      outer_area = twice;  // the largest outer boundary represents the outer face
      g.faces_[0].edge = e0;
    }
    e = e0;
    do {
      g.edges_[e].face = f;
      e = g.edges_[e].next;
    } while (e != e0);
  }

  // Connected components (isolated junctions count).
  {
    std::vector<uint32_t> parent(nj);
    std::iota(parent.begin(), parent.end(), 0u);
    auto find = [&](uint32_t x) {
      while (parent[x] != x) x = parent[x] = parent[parent[x]];
      return x;
    };
    size_t comps = nj;
    for (const Street& s : g.streets_) {
      uint32_t ra = find(s.a), rb = find(s.b);
      if (ra != rb) {
        parent[ra] = rb;
        --comps;
      }
    }
    g.components_ = comps;
  }

  g.buildIndex();

  if (check_planarity) {
    // Test every pair of streets listed in a common grid cell.
    const auto& st = g.streets_;
    for (int c = 0; c < g.grid_nx_ * g.grid_ny_; ++c) {
      const uint32_t b = g.grid_start_[c], en = g.grid_start_[c + 1];
      for (uint32_t i = b; i < en; ++i) {
        const uint32_t s = g.grid_streets_[i];
        const DVec2 a0 = d2(pos[st[s].a]), a1 = d2(pos[st[s].b]);
        for (uint32_t k = i + 1; k < en; ++k) {
          const uint32_t t = g.grid_streets_[k];
          const Street& u = st[t];
          const bool share = u.a == st[s].a || u.a == st[s].b || u.b == st[s].a || u.b == st[s].b;
          if (share) continue;  // overlaps of adjacent streets are found around the junctions above
          const DVec2 b0 = d2(pos[u.a]), b1 = d2(pos[u.b]);
          if (segmentsIntersectD(a0, a1, b0, b1)) {
            uint32_t lo = std::min(s, t), hi = std::max(s, t);
            throw Error(source, "streets " + std::to_string(lo) + " and " + std::to_string(hi) + " cross near " +
                                    fmtPoint(contactPoint(a0, a1, b0, b1)) + " (the street graph must be planar)");
          }
        }
      }
    }
  }
  return g;
}

void StreetGraph::buildIndex() {
  SegmentGrid grid;
  grid.build(positions_, streets_);
  grid_box_ = grid.box;
  grid_cell_ = grid.cell;
  grid_nx_ = grid.nx;
  grid_ny_ = grid.ny;
  grid_start_ = std::move(grid.start);
  grid_streets_ = std::move(grid.items);
}

// Visits the streets listed in rings of grid cells around p, nearest rings first. visit(street) returns the
// distance below which nothing farther can matter; the search stops when the next ring lies beyond it.
template <class Visit>
void StreetGraph::searchNear(const Vec2& p, Visit&& visit) const {
  if (grid_nx_ == 0) return;
  const int cx = std::clamp(int(std::floor((p.x - grid_box_.lo.x) / grid_cell_)), 0, grid_nx_ - 1);
  const int cy = std::clamp(int(std::floor((p.y - grid_box_.lo.y) / grid_cell_)), 0, grid_ny_ - 1);
  const int max_r = std::max(grid_nx_, grid_ny_);
  double bound = std::numeric_limits<double>::infinity();
  for (int r = 0; r <= max_r; ++r) {
    // Cells not visited yet are r or more cells away from (cx, cy) along some axis, so at least (r - 1) cell
    // sizes away from p (also when p lies outside the grid and was clamped into it).
    if (double(r - 1) * grid_cell_ > bound) break;
    for (int y = cy - r; y <= cy + r; ++y) {
      if (y < 0 || y >= grid_ny_) continue;
      const bool edge_row = (y == cy - r || y == cy + r);
      for (int x = cx - r; x <= cx + r; x += (edge_row ? 1 : 2 * r)) {
        if (x >= 0 && x < grid_nx_) {
          const size_t c = size_t(y) * grid_nx_ + x;
          for (uint32_t i = grid_start_[c]; i < grid_start_[c + 1]; ++i) bound = visit(grid_streets_[i]);
        }
        if (r == 0) break;
      }
    }
  }
}

float StreetGraph::length(uint32_t e) const { return glm::length(destinationPosition(e) - originPosition(e)); }

Vec2 StreetGraph::direction(uint32_t e) const {
  Vec2 d = destinationPosition(e) - originPosition(e);
  float l = glm::length(d);
  return l > 0.0f ? d / l : Vec2(0.0f);
}

std::vector<uint32_t> StreetGraph::outgoing(uint32_t junction) const {
  std::vector<uint32_t> list;
  const uint32_t e0 = junction_edge_[junction];
  if (e0 == kNone) return list;
  // prev(e) ends at origin(e) and e = next(prev(e)) leaves just clockwise of twin(prev(e)), so twin(prev(e)) is the
  // next outgoing half-edge counter-clockwise.
  uint32_t e = e0;
  do {
    list.push_back(e);
    e = twin(prev(e));
  } while (e != e0 && list.size() <= edges_.size());
  return list;
}

size_t StreetGraph::degree(uint32_t junction) const { return outgoing(junction).size(); }

std::vector<uint32_t> StreetGraph::edgesOfFace(uint32_t face) const {
  std::vector<uint32_t> list;
  const uint32_t e0 = faces_.at(face).edge;
  if (e0 == kNone) return list;
  uint32_t e = e0;
  do {
    list.push_back(e);
    e = next(e);
  } while (e != e0 && list.size() <= edges_.size());
  return list;
}

std::vector<uint32_t> StreetGraph::faceBoundary(uint32_t face) const {
  std::vector<uint32_t> loop;
  for (uint32_t e : edgesOfFace(face)) loop.push_back(origin(e));
  return loop;
}

Polygon2 StreetGraph::facePolygon(uint32_t face) const {
  Polygon2 poly;
  for (uint32_t e : edgesOfFace(face)) poly.push_back(originPosition(e));
  return poly;
}

std::vector<uint32_t> StreetGraph::blocksOfEdge(uint32_t e, bool include_outer) const {
  std::vector<uint32_t> list;
  for (uint32_t f : {face(e), face(twin(e))}) {
    if (!include_outer && faces_[f].outer) continue;
    if (std::find(list.begin(), list.end(), f) == list.end()) list.push_back(f);
  }
  return list;
}

std::vector<uint32_t> StreetGraph::blocksAtJunction(uint32_t junction, bool include_outer) const {
  std::vector<uint32_t> list;
  for (uint32_t e : outgoing(junction)) {
    uint32_t f = face(e);
    if (!include_outer && faces_[f].outer) continue;
    if (std::find(list.begin(), list.end(), f) == list.end()) list.push_back(f);
  }
  return list;
}

float StreetGraph::distanceToEdge(const Vec2& p, uint32_t e) const {
  return float(distancePointSegmentD(d2(p), d2(originPosition(e)), d2(destinationPosition(e))));
}

uint32_t StreetGraph::nearestOrientedEdge(const Vec2& p, const Vec2& heading) const {
  if (streets_.empty()) return kNone;
  constexpr double kTie = 0.01;  // metres
  const DVec2 h = d2(heading);
  const bool has_heading = glm::dot(h, h) > 0.0;
  struct Best {
    uint32_t e = kNone;
    double d = std::numeric_limits<double>::infinity();
    double align = -2.0;
    void offer(uint32_t edge, double dist, double a) {
      if (e == kNone || dist < d - kTie || (dist <= d + kTie && a > align)) {
        e = edge;
        d = dist;
        align = a;
      }
    }
  };
  Best agree, any;
  const DVec2 hn = has_heading ? h / glm::length(h) : DVec2(0.0);
  auto visit = [&](uint32_t s) {
    const DVec2 a = d2(positions_[streets_[s].a]), b = d2(positions_[streets_[s].b]);
    const double dist = distancePointSegmentD(d2(p), a, b);
    const DVec2 dir = glm::normalize(b - a);
    const double c = glm::dot(dir, hn);
    // Half-edge 2s runs a -> b (alignment c), 2s + 1 runs b -> a (alignment -c).
    if (c > 0.0) agree.offer(2 * s, dist, c);
    if (-c > 0.0) agree.offer(2 * s + 1, dist, -c);
    any.offer(c >= 0.0 ? 2 * s : 2 * s + 1, dist, std::abs(c));
    return (agree.e != kNone ? agree.d : any.d) + kTie;
  };
  if (has_heading) {
    searchNear(p, visit);
    if (agree.e == kNone) {
      // Nothing agreed within reach of the nearest street: scan all (rare: heading perpendicular to every street).
      for (uint32_t s = 0; s < streets_.size(); ++s) visit(s);
    }
    if (agree.e != kNone) return agree.e;
    return any.e;
  }
  searchNear(p, visit);
  return any.e;
}

uint32_t StreetGraph::nearestStreet(const Vec2& p) const {
  if (streets_.empty()) return kNone;
  uint32_t best = kNone;
  double best_d = std::numeric_limits<double>::infinity();
  searchNear(p, [&](uint32_t s) {
    double d = distancePointSegmentD(d2(p), d2(positions_[streets_[s].a]), d2(positions_[streets_[s].b]));
    if (d < best_d || (d == best_d && s < best)) {
      best_d = d;
      best = s;
    }
    return best_d;
  });
  return best;
}

Box2 StreetGraph::bounds() const {
  Box2 b;
  for (const Vec2& p : positions_) b.expand(p);
  return b;
}

// ---- JSON -------------------------------------------------------------------------------------------------------

nlohmann::json StreetGraph::toJson() const {
  using nlohmann::json;
  json j;
  j["format"] = "farfield-streets";
  j["version"] = 1;
  json junctions = json::array();
  for (const Vec2& p : positions_) junctions.push_back(json::array({p.x, p.y}));
  j["junctions"] = std::move(junctions);
  json streets = json::array();
  for (const Street& s : streets_)
    streets.push_back(json{{"a", s.a}, {"b", s.b}, {"width", s.width}, {"class", s.street_class}});
  j["streets"] = std::move(streets);
  json faces = json::array();
  for (uint32_t f = 0; f < faces_.size(); ++f) faces.push_back(json{{"outer", faces_[f].outer}, {"junctions", faceBoundary(f)}});
  j["faces"] = std::move(faces);
  return j;
}

StreetGraph StreetGraph::fromJson(const nlohmann::json& j, const std::string& source) {
  if (!j.is_object()) throw Error(source, "expected a JSON object with \"junctions\" and \"streets\"");
  if (j.contains("format") && j["format"] != "farfield-streets")
    throw Error(source, "format is not \"farfield-streets\"");
  if (j.contains("version") && (!j["version"].is_number_integer() || j["version"].get<int64_t>() != 1))
    throw Error(source, "unsupported version (expected 1)");
  if (!j.contains("junctions") || !j["junctions"].is_array()) throw Error(source, "missing \"junctions\" array");
  if (!j.contains("streets") || !j["streets"].is_array()) throw Error(source, "missing \"streets\" array");
  const auto& jj = j["junctions"];
  std::vector<Vec2> junctions;
  junctions.reserve(jj.size());
  for (size_t i = 0; i < jj.size(); ++i) {
    const auto& p = jj[i];
    if (!p.is_array() || p.size() != 2 || !p[0].is_number() || !p[1].is_number())
      throw Error(source, "junction " + std::to_string(i) + ": expected [x, y] numbers");
    Vec2 v(p[0].get<double>(), p[1].get<double>());
    if (!isFinite(v)) throw Error(source, "junction " + std::to_string(i) + ": non-finite position");
    junctions.push_back(v);
  }
  const auto& js = j["streets"];
  std::vector<Street> streets;
  streets.reserve(js.size());
  for (size_t i = 0; i < js.size(); ++i) {
    const auto& s = js[i];
    const std::string where = "street " + std::to_string(i) + ": ";
    if (!s.is_object()) throw Error(source, where + "expected an object {\"a\", \"b\", \"width\", \"class\"}");
    Street st;
    for (const char* key : {"a", "b"}) {
      if (!s.contains(key) || !s[key].is_number_integer() || s[key].get<int64_t>() < 0 ||
          s[key].get<int64_t>() >= int64_t(kNone))
        throw Error(source, where + "\"" + key + "\" must be a junction index");
    }
    st.a = uint32_t(s["a"].get<int64_t>());
    st.b = uint32_t(s["b"].get<int64_t>());
    if (s.contains("class")) {
      if (!s["class"].is_number_integer()) throw Error(source, where + "\"class\" must be an integer");
      st.street_class = int(s["class"].get<int64_t>());
    }
    if (s.contains("width")) {
      if (!s["width"].is_number()) throw Error(source, where + "\"width\" must be a number");
      st.width = float(s["width"].get<double>());
    }
    streets.push_back(st);
  }
  return build(std::move(junctions), std::move(streets), source, true);
}

StreetGraph StreetGraph::load(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path, "cannot open street graph file");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw Error(path, std::string("not valid JSON: ") + e.what());
  }
  return fromJson(j, path);
}

void StreetGraph::save(const std::string& path) const {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw Error(path, "cannot write street graph file");
  out << toJson().dump() << '\n';
  if (!out) throw Error(path, "write failed");
}

}  // namespace farfield::urban
