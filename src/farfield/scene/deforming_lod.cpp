// Deformation-sensitive decimation by half-edge collapses over welded points, with the poses' quadrics summed; the
// levels' distances measured with CGAL's AABB trees. This is the scene module's one translation unit that includes
// CGAL.
#include "farfield/scene/deforming_lod.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <queue>
#include <unordered_map>

#include "farfield/core/check.h"
#include "farfield/core/error.h"
#include "farfield/core/log.h"
#include "farfield/scene/texture_deviation.h"

namespace farfield::scene {

namespace {

using DVec3 = glm::dvec3;

// Sum of weighted squared distances to planes (Garland and Heckbert's quadric), as the ten terms of a symmetric
// 4x4 matrix.
struct Quadric {
  std::array<double, 10> q{};  // aa ab ac ad bb bc bd cc cd dd

  void addPlane(const DVec3& n, double d, double w) {
    const double p[4] = {n.x, n.y, n.z, d};
    int k = 0;
    for (int i = 0; i < 4; ++i)
      for (int j = i; j < 4; ++j) q[size_t(k++)] += w * p[i] * p[j];
  }
  Quadric& operator+=(const Quadric& o) {
    for (size_t k = 0; k < q.size(); ++k) q[k] += o.q[k];
    return *this;
  }
  double operator()(const DVec3& v) const {
    const double x = v.x, y = v.y, z = v.z;
    return q[0] * x * x + 2 * q[1] * x * y + 2 * q[2] * x * z + 2 * q[3] * x + q[4] * y * y + 2 * q[5] * y * z +
           2 * q[6] * y + q[7] * z * z + 2 * q[8] * z + q[9];
  }
};

void validate(std::span<const uint32_t> indices, std::span<const std::vector<Vec3>> poses, const std::string& source) {
  if (poses.empty()) throw Error(source, "deforming LOD: no pose");
  if (indices.size() % 3 != 0)
    throw Error(source, "deforming LOD: " + std::to_string(indices.size()) + " indices, not whole triangles");
  const size_t n = poses[0].size();
  for (size_t p = 0; p < poses.size(); ++p) {
    if (poses[p].size() != n)
      throw Error(source, "deforming LOD: pose " + std::to_string(p) + " has " + std::to_string(poses[p].size()) +
                              " vertices, pose 0 " + std::to_string(n));
    for (size_t v = 0; v < n; ++v)
      if (!std::isfinite(poses[p][v].x) || !std::isfinite(poses[p][v].y) || !std::isfinite(poses[p][v].z))
        throw Error(source, "deforming LOD: pose " + std::to_string(p) + ", vertex " + std::to_string(v) +
                                ": non-finite position");
  }
  for (size_t i = 0; i < indices.size(); ++i)
    if (indices[i] >= n)
      throw Error(source, "deforming LOD: index " + std::to_string(i) + " is " + std::to_string(indices[i]) +
                              ", past the " + std::to_string(n) + " vertices");
}

class Simplifier {
 public:
  Simplifier(std::span<const uint32_t> indices, std::span<const std::vector<Vec3>> poses,
             std::span<const uint32_t> groups, std::span<const Vec2> uvs, double max_turn_deg)
      : poses_(poses), groups_(groups), cos_turn_(std::cos(max_turn_deg * kPi / 180.0)) {
    weld();
    side_.resize(point_of_.size());
    for (const std::vector<uint32_t>& vertices : points_)
      for (uint32_t v : vertices) {
        side_[v] = v;
        if (!uvs.empty())
          for (uint32_t w : vertices)
            if (uvs[w] == uvs[v]) {
              side_[v] = w;  // the point's first vertex of this uv
              break;
            }
      }
    for (size_t t = 0; t * 3 < indices.size(); ++t) {
      const std::array<uint32_t, 3> c{indices[3 * t], indices[3 * t + 1], indices[3 * t + 2]};
      if (point_of_[c[0]] == point_of_[c[1]] || point_of_[c[1]] == point_of_[c[2]] ||
          point_of_[c[0]] == point_of_[c[2]])
        continue;  // degenerate in every pose: dropped from every level
      tris_.push_back(c);
      source_.push_back(uint32_t(t));
    }
    alive_.assign(tris_.size(), 1);
    live_ = tris_.size();
    point_tris_.resize(points_.size());
    for (uint32_t t = 0; t < tris_.size(); ++t)
      for (uint32_t c : tris_[t]) point_tris_[point_of_[c]].push_back(t);
    initQuadrics();
    point_alive_.assign(points_.size(), 1);
    version_.assign(points_.size(), 0);
    for (uint32_t u = 0; u < points_.size(); ++u) pushBest(u);
  }

  size_t liveTriangles() const { return live_; }

  // Collapses until at most `target` triangles are left; false when no collapse is left before that.
  bool reduceTo(size_t target) {
    while (live_ > target) {
      if (heap_.empty()) return false;
      const Entry e = heap_.top();
      heap_.pop();
      if (!point_alive_[e.u] || e.version != version_[e.u]) continue;
      if (!point_alive_[e.v] || !valid(e.u, e.v)) {
        ++version_[e.u];
        pushBest(e.u);
        continue;
      }
      collapse(e.u, e.v);
    }
    return true;
  }

  // The live triangles as a level (its distance not measured).
  DeformingLevel level() const {
    DeformingLevel out;
    out.indices.reserve(live_ * 3);
    out.source_triangles.reserve(live_);
    for (size_t t = 0; t < tris_.size(); ++t)
      if (alive_[t]) {
        out.indices.insert(out.indices.end(), tris_[t].begin(), tris_[t].end());
        out.source_triangles.push_back(source_[t]);
      }
    return out;
  }

 private:
  struct Entry {
    double cost;
    uint32_t u, v, version;
    bool operator<(const Entry& o) const { return cost > o.cost; }  // least cost on top
  };

  DVec3 pos(size_t pose, uint32_t point) const { return DVec3(poses_[pose][points_[point][0]]); }
  uint32_t pointOf(uint32_t t, int corner) const { return point_of_[tris_[t][size_t(corner)]]; }
  bool hasPoint(uint32_t t, uint32_t w) const { return pointOf(t, 0) == w || pointOf(t, 1) == w || pointOf(t, 2) == w; }

  // Vertices at the same position in every pose become one point.
  void weld() {
    const size_t n = poses_[0].size();
    point_of_.resize(n);
    std::unordered_map<uint64_t, std::vector<uint32_t>> by_hash;
    for (uint32_t v = 0; v < n; ++v) {
      uint64_t h = 1469598103934665603ull;
      uint32_t bits[3];
      std::memcpy(bits, &poses_[0][v], sizeof(bits));
      for (uint32_t b : bits) h = (h ^ b) * 1099511628211ull;
      std::vector<uint32_t>& bucket = by_hash[h];
      uint32_t found = UINT32_MAX;
      for (uint32_t p : bucket) {
        const uint32_t w = points_[p][0];
        bool same = true;
        for (size_t k = 0; k < poses_.size() && same; ++k) same = poses_[k][v] == poses_[k][w];
        if (same) {
          found = p;
          break;
        }
      }
      if (found == UINT32_MAX) {
        found = uint32_t(points_.size());
        points_.emplace_back();
        bucket.push_back(found);
      }
      points_[found].push_back(v);
      point_of_[v] = found;
    }
  }

  // Each pose's face planes weighted by the square root of their area, and the planes through feature edges
  // perpendicular to their face, weighted by ten times the edge's length. Weights by area (Garland and Heckbert's)
  // made small, pointed parts cheap to merge away: CesiumMan's 584-triangle level was 4.1 cm off, 2.2 cm with these
  // (and unweighted planes 2.4 cm, with the finer levels worse).
  void initQuadrics() {
    const size_t k = poses_.size();
    quadrics_.assign(points_.size() * k, Quadric{});
    // Per edge: its triangles, and whether they differ in group (a feature, as the surface's border is).
    struct Uses {
      int count = 0;
      uint32_t group = 0;
      bool mixed = false;
    };
    std::unordered_map<uint64_t, Uses> edge_uses;
    auto key = [](uint32_t a, uint32_t b) { return (uint64_t(std::min(a, b)) << 32) | std::max(a, b); };
    for (uint32_t t = 0; t < tris_.size(); ++t)
      for (int c = 0; c < 3; ++c) {
        Uses& e = edge_uses[key(pointOf(t, c), pointOf(t, (c + 1) % 3))];
        if (e.count++ == 0) e.group = group(t);
        e.mixed = e.mixed || e.group != group(t);
      }
    for (size_t p = 0; p < k; ++p)
      for (uint32_t t = 0; t < tris_.size(); ++t) {
        const uint32_t i[3] = {pointOf(t, 0), pointOf(t, 1), pointOf(t, 2)};
        const DVec3 a = pos(p, i[0]), b = pos(p, i[1]), c = pos(p, i[2]);
        const DVec3 cr = glm::cross(b - a, c - a);
        const double len = glm::length(cr);
        if (!(len > 0.0)) continue;
        const DVec3 n = cr / len;
        for (uint32_t pt : i) quadrics_[pt * k + p].addPlane(n, -glm::dot(n, a), std::sqrt(0.5 * len));
        for (int c = 0; c < 3; ++c) {
          const uint32_t u = i[c], v = i[(c + 1) % 3];
          const Uses& e = edge_uses[key(u, v)];
          if (e.count != 1 && !e.mixed) continue;
          const DVec3 pu = pos(p, u), ev = pos(p, v) - pu;
          const DVec3 m = glm::cross(ev, n);
          const double ml = glm::length(m);
          if (!(ml > 0.0)) continue;
          const double w = 10.0 * glm::length(ev);  // features held ten times as firmly as faces
          for (uint32_t pt : {u, v}) quadrics_[pt * k + p].addPlane(m / ml, -glm::dot(m / ml, pu), w);
        }
      }
  }

  void neighbours(uint32_t u, std::vector<uint32_t>& out) const {
    out.clear();
    for (uint32_t t : point_tris_[u]) {
      if (!alive_[t]) continue;
      for (int c = 0; c < 3; ++c) {
        const uint32_t w = pointOf(t, c);
        if (w != u && std::find(out.begin(), out.end(), w) == out.end()) out.push_back(w);
      }
    }
  }

  // Which vertex of v each vertex of u becomes: the one beside a vertex of u's side in a triangle of the edge, so that
  // a point split by a seam merges along the seam, each side into its own side. A side is the vertex itself, or with
  // uvs all the point's vertices of one uv (normals split for flat shading). False when a vertex of u that triangles
  // use has no such vertex (its side does not reach v) or vertices of two sides.
  bool mapping(uint32_t u, uint32_t v) {
    map_.clear();
    for (uint32_t a : points_[u]) {
      uint32_t b = UINT32_MAX;
      bool used = false;
      for (uint32_t t : point_tris_[u]) {
        if (!alive_[t]) continue;
        const std::array<uint32_t, 3>& c = tris_[t];
        used = used || c[0] == a || c[1] == a || c[2] == a;
        uint32_t at_u = UINT32_MAX, at_v = UINT32_MAX;
        for (uint32_t x : c) {
          if (point_of_[x] == u) at_u = x;
          if (point_of_[x] == v) at_v = x;
        }
        if (at_v == UINT32_MAX || side_[at_u] != side_[a]) continue;
        if (b != UINT32_MAX && side_[b] != side_[at_v]) return false;
        if (b == UINT32_MAX) b = at_v;
      }
      if (!used) continue;
      if (b == UINT32_MAX) return false;
      map_.push_back({a, b});
    }
    return true;
  }

  uint32_t group(uint32_t t) const { return groups_.empty() ? 0u : groups_[source_[t]]; }

  // Whether the edge u-w is a feature: the surface's border (one triangle) or a border between groups.
  bool feature(uint32_t u, uint32_t w) const {
    uint32_t first = UINT32_MAX;
    int count = 0;
    for (uint32_t t : point_tris_[u]) {
      if (!alive_[t] || !hasPoint(t, w)) continue;
      if (count++ == 0)
        first = group(t);
      else if (group(t) != first)
        return true;
    }
    return count == 1;
  }

  // u may leave its place: inside a region (no feature edge), or along its feature line (exactly two feature
  // edges, the edge to v one of them); a point where features meet or end stays.
  bool featureAllows(uint32_t u, uint32_t v) const {
    int features = 0;
    bool along = false;
    for (uint32_t w : nu_)
      if (feature(u, w)) {
        ++features;
        along = along || w == v;
      }
    return features == 0 || (features == 2 && along);
  }

  // u may merge into v: they share an edge, u stays on its feature line (featureAllows), every vertex of u has its
  // vertex of v (mapping), the link condition holds (the surface stays a manifold) and no triangle around u folds or
  // degenerates in any pose.
  bool valid(uint32_t u, uint32_t v) {
    neighbours(u, nu_);
    if (std::find(nu_.begin(), nu_.end(), v) == nu_.end() || !featureAllows(u, v)) return false;
    neighbours(v, nv_);
    size_t shared_tris = 0, common = 0;
    for (uint32_t t : point_tris_[u])
      if (alive_[t] && hasPoint(t, v)) ++shared_tris;
    for (uint32_t w : nu_) common += std::find(nv_.begin(), nv_.end(), w) != nv_.end() ? 1 : 0;
    if (common != shared_tris || !mapping(u, v)) return false;
    for (uint32_t t : point_tris_[u]) {
      if (!alive_[t]) continue;
      if (hasPoint(t, v)) continue;
      const uint32_t i[3] = {pointOf(t, 0), pointOf(t, 1), pointOf(t, 2)};
      for (size_t p = 0; p < poses_.size(); ++p) {
        DVec3 q[3], r[3];
        for (int c = 0; c < 3; ++c) {
          q[c] = pos(p, i[c]);
          r[c] = i[c] == u ? pos(p, v) : q[c];
        }
        const DVec3 n0 = glm::cross(q[1] - q[0], q[2] - q[0]);
        const DVec3 n1 = glm::cross(r[1] - r[0], r[2] - r[0]);
        const double l0 = glm::length(n0), l1 = glm::length(n1);
        if (!(l1 > 1e-6 * l0) || glm::dot(n0, n1) < cos_turn_ * l0 * l1) return false;
      }
    }
    return true;
  }

  double cost(uint32_t u, uint32_t v) const {
    const size_t k = poses_.size();
    double c = 0.0;
    for (size_t p = 0; p < k; ++p) {
      const DVec3 x = pos(p, v);
      c += quadrics_[u * k + p](x) + quadrics_[v * k + p](x);
    }
    return c;
  }

  void pushBest(uint32_t u) {
    if (!point_alive_[u]) return;
    neighbours(u, cand_);  // cost and valid use their own scratch lists
    Entry best{std::numeric_limits<double>::infinity(), u, u, version_[u]};
    for (uint32_t v : cand_) {
      const double c = cost(u, v);
      if (c < best.cost && valid(u, v)) best = {c, u, v, version_[u]};
    }
    if (best.v != u) heap_.push(best);
  }

  void collapse(uint32_t u, uint32_t v) {
    const bool mapped = mapping(u, v);
    FF_CHECK(mapped);
    for (uint32_t t : point_tris_[u]) {
      if (!alive_[t]) continue;
      if (hasPoint(t, v)) {
        alive_[t] = 0;
        --live_;
        continue;
      }
      for (uint32_t& c : tris_[t])
        for (const auto& [a, b] : map_)
          if (c == a) {
            c = b;
            break;
          }
      point_tris_[v].push_back(t);
    }
    point_alive_[u] = 0;
    point_tris_[u].clear();
    std::erase_if(point_tris_[v], [&](uint32_t t) { return !alive_[t]; });
    const size_t k = poses_.size();
    for (size_t p = 0; p < k; ++p) quadrics_[v * k + p] += quadrics_[u * k + p];
    neighbours(v, around_);  // pushBest fills cand_, not around_
    for (uint32_t w : around_) {
      ++version_[w];
      pushBest(w);
    }
    ++version_[v];
    pushBest(v);
  }

  std::span<const std::vector<Vec3>> poses_;
  std::span<const uint32_t> groups_;  // per mesh triangle; empty: one group
  double cos_turn_;
  std::vector<uint32_t> point_of_;             // vertex -> point
  std::vector<uint32_t> side_;                 // vertex -> its side of its point (mapping)
  std::vector<std::vector<uint32_t>> points_;  // point -> its vertices
  std::vector<std::array<uint32_t, 3>> tris_;  // corners as vertices
  std::vector<uint32_t> source_;               // per triangle: its index in the mesh
  std::vector<uint8_t> alive_, point_alive_;
  size_t live_ = 0;
  std::vector<std::vector<uint32_t>> point_tris_;
  std::vector<Quadric> quadrics_;  // point * poses + pose
  std::vector<uint32_t> version_;
  std::priority_queue<Entry> heap_;
  std::vector<uint32_t> nu_, nv_, cand_, around_;
  std::vector<std::pair<uint32_t, uint32_t>> map_;  // mapping(): u's vertices to v's
};

using Kernel = CGAL::Simple_cartesian<double>;
using Triangle = Kernel::Triangle_3;
using Point = Kernel::Point_3;
using Primitive = CGAL::AABB_triangle_primitive<Kernel, std::vector<Triangle>::const_iterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;

Point point(const Vec3& v) { return Point(v.x, v.y, v.z); }

// The pose's non-degenerate triangles.
std::vector<Triangle> triangles(std::span<const uint32_t> indices, const std::vector<Vec3>& pose) {
  std::vector<Triangle> out;
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    const Triangle tri(point(pose[indices[t]]), point(pose[indices[t + 1]]), point(pose[indices[t + 2]]));
    if (!tri.is_degenerate()) out.push_back(tri);
  }
  return out;
}

}  // namespace

double deformingDistance(std::span<const uint32_t> full, std::span<const uint32_t> level,
                         std::span<const std::vector<Vec3>> poses) {
  double worst2 = 0.0;
  std::vector<uint8_t> used;
  for (const std::vector<Vec3>& pose : poses) {
    const std::vector<Triangle> full_tris = triangles(full, pose), level_tris = triangles(level, pose);
    if (full_tris.empty() || level_tris.empty()) continue;
    Tree full_tree(full_tris.begin(), full_tris.end()), level_tree(level_tris.begin(), level_tris.end());
    full_tree.accelerate_distance_queries();
    level_tree.accelerate_distance_queries();
    used.assign(pose.size(), 0);
    for (uint32_t i : full) used[i] = 1;
    for (size_t v = 0; v < pose.size(); ++v)
      if (used[v]) worst2 = std::max(worst2, level_tree.squared_distance(point(pose[v])));
    for (const Triangle& t : level_tris) {
      const Point c = CGAL::centroid(t);
      worst2 = std::max(worst2, full_tree.squared_distance(c));
      for (int e = 0; e < 3; ++e)
        worst2 = std::max(worst2, full_tree.squared_distance(CGAL::midpoint(t[e], t[(e + 1) % 3])));
    }
  }
  return std::sqrt(worst2);
}

std::vector<DeformingLevel> deformingLevels(std::span<const uint32_t> indices,
                                            std::span<const std::vector<Vec3>> poses,
                                            const DeformingLodOptions& options, const std::string& source,
                                            std::span<const uint32_t> triangle_groups, std::span<const Vec2> uvs) {
  validate(indices, poses, source);
  if (!uvs.empty() && uvs.size() != poses[0].size())
    throw Error(source, "deforming LOD: " + std::to_string(uvs.size()) + " uvs for " +
                            std::to_string(poses[0].size()) + " vertices");
  if (!triangle_groups.empty() && triangle_groups.size() * 3 != indices.size())
    throw Error(source, "deforming LOD: " + std::to_string(triangle_groups.size()) + " triangle groups for " +
                            std::to_string(indices.size() / 3) + " triangles");
  for (size_t i = 0; i < options.triangle_ratios.size(); ++i) {
    const double r = options.triangle_ratios[i];
    if (!(r > 0.0 && r < 1.0) || (i > 0 && !(r < options.triangle_ratios[i - 1])))
      throw Error(source, "deforming LOD: triangle ratios must decrease within (0, 1)");
  }
  Simplifier simplifier(indices, poses, triangle_groups, uvs, options.max_normal_turn_deg);
  const size_t start = simplifier.liveTriangles();
  std::vector<DeformingLevel> levels;
  for (double r : options.triangle_ratios) {
    if (!simplifier.reduceTo(size_t(std::floor(r * double(start))))) {
      FF_INFO(source << ": levels of detail stop at " << simplifier.liveTriangles() << " of " << start
                     << " triangles: no merge left that keeps seams, features and every pose's orientation");
      break;
    }
    DeformingLevel level = simplifier.level();
    level.error = deformingDistance(indices, level.indices, poses);
    if (!uvs.empty()) level.texture_error = textureDeviation(indices, level.indices, poses, uvs);
    levels.push_back(std::move(level));
  }
  return levels;
}

}  // namespace farfield::scene
