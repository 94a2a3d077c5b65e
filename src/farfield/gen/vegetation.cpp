// Procedural trees, street rows, parks and a forest (steed-ibr-impostors-lecture, part 2, "the simplest impostor:
// the billboard": the geometry billboards replace). A crown is a cloud of small leaf triangles, as real tree models
// are: many triangles, much alpha-like see-through between them, which is what makes trees expensive as geometry
// and cheap as images.
#include "farfield/gen/vegetation.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "farfield/core/error.h"
#include "farfield/gen/buildings.h"

namespace farfield::gen {
namespace {

void checkTree(const TreeOptions& o, const std::string& where) {
  if (!(o.height > 0.5f && o.height < 200.0f)) throw Error(where, "tree height outside 0.5..200 m");
  if (!(o.crown_radius > 0.1f && o.crown_radius < 100.0f)) throw Error(where, "crown radius outside 0.1..100 m");
  if (o.leaves < 1 || o.leaves > 100000) throw Error(where, "leaves outside 1..100000");
  if (!(o.leaf_size > 0.01f && o.leaf_size < 10.0f)) throw Error(where, "leaf size outside 0.01..10 m");
}

Vec3 randomUnit(Rng& rng) {
  for (;;) {
    const Vec3 v(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    const float l = glm::length(v);
    if (l > 0.05f && l <= 1.0f) return v / l;
  }
}

}  // namespace

TreeMeshes makeTree(const TreeOptions& options, uint64_t seed, const Vec3& base) {
  checkTree(options, "makeTree");
  if (!isFinite(base)) throw Error("makeTree", "base is not finite");
  Rng rng(mixSeed(seed, 0x7e3e));
  TreeMeshes t;
  const float h = options.height;
  const Vec3 crown_centre = base + Vec3(0, 0, 0.62f * h);
  const Vec3 radii(options.crown_radius, options.crown_radius, 0.38f * h);

  // Trunk: six sides, tapering, up to the crown's centre.
  constexpr int kSides = 6;
  const float r0 = std::clamp(0.035f * h, 0.08f, 1.5f), r1 = 0.5f * r0, top = 0.62f * h;
  for (int i = 0; i <= kSides; ++i) {
    const float a = float(2 * kPi) * float(i % kSides) / kSides;
    const Vec3 dir(std::cos(a), std::sin(a), 0.0f);
    t.trunk.positions.push_back(base + r0 * dir + Vec3(0, 0, -0.3f));
    t.trunk.positions.push_back(base + r1 * dir + Vec3(0, 0, top));
    t.trunk.normals.push_back(dir);
    t.trunk.normals.push_back(dir);
  }
  for (uint32_t i = 0; i < kSides; ++i) {
    const uint32_t a = 2 * i, b = a + 1, c = a + 2, d = a + 3;
    t.trunk.indices.insert(t.trunk.indices.end(), {a, c, d, a, d, b});
  }

  // Leaves: triangles at random points of the ellipsoid (denser towards its surface, as foliage is), random
  // orientation, normal away from the centre.
  const float s = options.leaf_size;
  for (int i = 0; i < options.leaves; ++i) {
    const Vec3 dir = randomUnit(rng);
    const float rad = std::cbrt(rng.uniform(0.15f, 1.0f));
    const Vec3 c = crown_centre + dir * radii * rad;
    const Vec3 n = glm::normalize(dir / radii);
    const Vec3 u = glm::normalize(glm::cross(randomUnit(rng), n + 0.3f * randomUnit(rng)));
    const Vec3 w = glm::normalize(glm::cross(n + 0.3f * randomUnit(rng), u));
    const uint32_t first = uint32_t(t.crown.positions.size());
    t.crown.positions.push_back(c + s * 0.6f * u);
    t.crown.positions.push_back(c - s * 0.3f * u + s * 0.5f * w);
    t.crown.positions.push_back(c - s * 0.3f * u - s * 0.5f * w);
    for (int k = 0; k < 3; ++k) t.crown.normals.push_back(n);
    t.crown.indices.insert(t.crown.indices.end(), {first, first + 1, first + 2});
  }
  t.trunk.computeBounds();
  t.crown.computeBounds();
  return t;
}

VegetationMaterials addVegetationMaterials(scene::Scene& scene) {
  VegetationMaterials m;
  scene::Material bark;
  bark.name = "bark";
  bark.base_color = Vec4(0.36f, 0.27f, 0.2f, 1.0f);
  m.bark = scene.addMaterial(std::move(bark));
  scene::Material leaves;
  leaves.name = "leaves";
  leaves.base_color = Vec4(0.25f, 0.45f, 0.17f, 1.0f);
  leaves.double_sided = true;
  m.leaves = scene.addMaterial(std::move(leaves));
  return m;
}

std::vector<Vec2> streetTreeSites(std::span<const Polygon2> footprints, float spacing, float offset) {
  if (!(spacing > 1.0f)) throw Error("streetTreeSites", "spacing must exceed 1 m");
  constexpr float kCornerGap = 4.0f;
  std::vector<Vec2> sites;
  for (const Polygon2& poly : footprints) {
    for (size_t i = 0; i < poly.size(); ++i) {
      const Vec2 a = poly[i], b = poly[(i + 1) % poly.size()];
      const float len = glm::length(b - a);
      const float usable = len - 2 * kCornerGap;
      if (len < spacing || usable <= 0.0f) continue;
      const Vec2 along = (b - a) / len;
      const Vec2 outward(along.y, -along.x);  // right of a counter-clockwise edge
      const int count = std::max(1, int(usable / spacing) + 1);
      const float step = count > 1 ? usable / float(count - 1) : 0.0f;
      for (int k = 0; k < count; ++k) {
        const float at = count > 1 ? kCornerGap + step * float(k) : 0.5f * len;
        sites.push_back(a + along * at + outward * offset);
      }
    }
  }
  return sites;
}

std::vector<Vec2> parkTreeSites(const Polygon2& polygon, float per_square_metre, float min_gap, float margin,
                                uint64_t seed) {
  std::vector<Vec2> sites;
  if (polygon.size() < 3) return sites;
  const Box2 box = polygonBounds(polygon);
  const double area = std::abs(signedArea(polygon));
  const size_t want = size_t(area * per_square_metre);
  Rng rng(mixSeed(seed, 0x9a4c));
  for (size_t tries = 0; sites.size() < want && tries < want * 30 + 30; ++tries) {
    const Vec2 p(rng.uniform(box.lo.x, box.hi.x), rng.uniform(box.lo.y, box.hi.y));
    if (!pointInPolygon(p, polygon) || distanceToBoundary(p, polygon) < margin) continue;
    bool close = false;
    for (const Vec2& q : sites) close = close || glm::length(p - q) < min_gap;
    if (!close) sites.push_back(p);
  }
  return sites;
}

std::vector<uint32_t> addTrees(scene::Scene& scene, std::span<const Vec2> sites,
                               const std::function<float(Vec2)>& ground, const TreeOptions& base, uint64_t seed,
                               const VegetationMaterials& materials) {
  checkTree(base, "addTrees");
  std::vector<uint32_t> ids;
  ids.reserve(sites.size());
  for (size_t i = 0; i < sites.size(); ++i) {
    Rng rng(mixSeed(seed, 0x51e0000 + i));
    TreeOptions o = base;
    const float scale = rng.uniform(0.8f, 1.25f);
    o.height *= scale;
    o.crown_radius *= scale * rng.uniform(0.85f, 1.15f);
    o.leaves = std::max(1, int(float(o.leaves) * rng.uniform(0.8f, 1.2f)));
    TreeMeshes t = makeTree(o, rng.next(), Vec3(sites[i], ground(sites[i])));
    scene::Object obj;
    obj.name = "tree";
    obj.parts.push_back({scene.addMesh(std::move(t.trunk)), materials.bark});
    obj.parts.push_back({scene.addMesh(std::move(t.crown)), materials.leaves});
    ids.push_back(scene.addObject(std::move(obj)));
  }
  return ids;
}

float forestGroundHeight(const ForestOptions& o, Vec2 p) {
  const float k = float(2 * kPi) / std::max(o.size, 1.0f);
  return o.relief * 0.5f * (std::sin(1.3f * k * p.x + 0.4f) * std::cos(1.7f * k * p.y) +
                            0.5f * std::sin(3.1f * k * (p.x + p.y) + 1.0f));
}

scene::Scene generateForest(const ForestOptions& o) {
  if (!(o.size >= 20.0f && o.size <= 20000.0f)) throw Error("forest", "size outside 20..20000 m");
  if (o.trees < 1 || o.trees > 200000) throw Error("forest", "trees outside 1..200000");
  if (!(o.relief >= 0.0f && o.relief <= 500.0f)) throw Error("forest", "relief outside 0..500 m");
  checkTree(o.tree, "forest");
  scene::Scene scene;
  scene::Material grass;
  grass.name = "grass";
  grass.base_color = Vec4(0.42f, 0.5f, 0.3f, 1.0f);
  const uint32_t grass_material = scene.addMaterial(std::move(grass));
  const VegetationMaterials materials = addVegetationMaterials(scene);

  // Ground grid, about 4 m cells.
  const int n = std::clamp(int(o.size / 4.0f), 4, 1024);
  const float half = 0.5f * o.size;
  scene::Mesh g;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const Vec2 p(-half + o.size * float(i) / float(n), -half + o.size * float(j) / float(n));
      g.positions.push_back(Vec3(p, forestGroundHeight(o, p)));
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const uint32_t a = uint32_t(j * (n + 1) + i), b = a + 1, c = a + uint32_t(n + 1), d = c + 1;
      g.indices.insert(g.indices.end(), {a, b, d, a, d, c});
    }
  g.computeNormals();
  g.computeBounds();
  scene::Object ground;
  ground.name = "ground";
  ground.parts.push_back({scene.addMesh(std::move(g)), grass_material});
  ground.footprint = {Vec2(-half, -half), Vec2(half, -half), Vec2(half, half), Vec2(-half, half)};
  scene.addObject(std::move(ground));

  const Polygon2 square{Vec2(-half, -half), Vec2(half, -half), Vec2(half, half), Vec2(-half, half)};
  const float density = float(o.trees) / (o.size * o.size);
  std::vector<Vec2> sites = parkTreeSites(square, density * 1.0001f, 3.0f, 2.0f, o.seed);
  addTrees(scene, sites, [&](Vec2 p) { return forestGroundHeight(o, p); }, o.tree, o.seed, materials);
  scene.updateBounds();
  return scene;
}

}  // namespace farfield::gen
