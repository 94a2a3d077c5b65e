// Procedural city for the walkthrough benchmark: a street graph whose oriented edges are the viewing cells and whose
// faces are the blocks (Sillion 1997 section 3; Decoret 1999 section 6 with its 146-block Montmartre model), blocks
// filled with buildings from their footprints inward, landmarks, an optional hill.
#include "farfield/gen/city.h"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include "farfield/core/error.h"
#include "farfield/core/progress.h"
#include "farfield/gen/buildings.h"
#include "farfield/gen/street_network.h"
#include "farfield/gen/textures.h"
#include "farfield/gen/vegetation.h"

namespace farfield::gen {

namespace {

constexpr int kMinBlocks = 10;
constexpr int kMaxBlocks = 200000;
constexpr float kGroundMargin = 40.0f;    // the ground reaches this far beyond the outermost streets
constexpr float kGroundTile = 8.0f;       // metres per asphalt texture repeat
constexpr float kBaseBelowGround = 1.0f;  // walls reach this far below the lowest ground under a building
constexpr int kProgressFromBlocks = 1000;

// The hill: a raised cosine of radius `radius` around the centre of the city, high enough to open panoramic views
// over the roofs (Montmartre rises about 130 m over 1 km) but capped so big cities are not mountains.
struct Hill {
  Vec2 centre{0.0f};
  float radius = 0.0f;
  float height = 0.0f;
};

Hill hillFor(const Box2& bounds) {
  Hill h;
  if (bounds.empty()) return h;
  h.centre = bounds.center();
  const Vec2 e = bounds.extent();
  h.radius = std::min(0.35f * std::min(e.x, e.y), 1500.0f);
  h.height = std::clamp(0.12f * h.radius, 12.0f, 130.0f);
  return h;
}

float hillHeight(const Hill& h, const Vec2& p) {
  if (h.radius <= 0.0f) return 0.0f;
  const float r = glm::length(p - h.centre);
  if (r >= h.radius) return 0.0f;
  return h.height * 0.5f * (1.0f + std::cos(float(kPi) * r / h.radius));
}

Vec3 hillNormal(const Hill& h, const Vec2& p) {
  const float r = glm::length(p - h.centre);
  if (h.radius <= 0.0f || r >= h.radius || r <= 0.0f) return Vec3(0.0f, 0.0f, 1.0f);
  // dh/dr of the raised cosine; the gradient points along p - centre.
  const float dhdr = -h.height * 0.5f * float(kPi) / h.radius * std::sin(float(kPi) * r / h.radius);
  const Vec2 g = (p - h.centre) / r * dhdr;
  return glm::normalize(Vec3(-g.x, -g.y, 1.0f));
}

// The ground under the city: flat, the hill, or CityOptions::ground.
class Ground {
 public:
  Ground(const CityOptions& o, const Box2& bounds)
      : hill_(hillFor(bounds)), with_hill_(o.hill), fn_(o.ground ? &o.ground : nullptr), centre_(bounds.center()) {}
  bool flat() const { return !with_hill_ && !fn_; }
  bool custom() const { return fn_ != nullptr; }
  const Hill& hill() const { return hill_; }
  float height(Vec2 p) const {
    if (fn_) return (*fn_)(p - centre_);
    return with_hill_ ? hillHeight(hill_, p) : 0.0f;
  }
  Vec3 normal(Vec2 p) const {
    if (!fn_) return with_hill_ ? hillNormal(hill_, p) : Vec3(0.0f, 0.0f, 1.0f);
    const float h = 0.5f;  // central differences over a metre
    const float dx = (height(p + Vec2(h, 0.0f)) - height(p - Vec2(h, 0.0f))) / (2.0f * h);
    const float dy = (height(p + Vec2(0.0f, h)) - height(p - Vec2(0.0f, h))) / (2.0f * h);
    return glm::normalize(Vec3(-dx, -dy, 1.0f));
  }

 private:
  Hill hill_;
  bool with_hill_;
  const std::function<float(Vec2)>* fn_;
  Vec2 centre_;
};

void validate(const CityOptions& o) {
  if (o.hill && o.ground) throw Error("city options", "a hill and a ground (terrain) exclude each other");
  if (o.ground && !(o.ground_cell >= 0.5f && std::isfinite(o.ground_cell)))
    throw Error("city options", "ground cell must be a finite number >= 0.5 m");
  if (o.blocks < kMinBlocks || o.blocks > kMaxBlocks)
    throw Error("city options", "blocks must be in [" + std::to_string(kMinBlocks) + ", " + std::to_string(kMaxBlocks) +
                                    "], got " + std::to_string(o.blocks));
  if (o.detail < 0 || o.detail > 4)
    throw Error("city options", "detail must be in [0, 4], got " + std::to_string(o.detail));
  if (o.objects != ObjectGrouping::Blocks && o.objects != ObjectGrouping::Buildings)
    throw Error("city options", "objects must be blocks or buildings");
  if (o.trees && !(o.tree_spacing > 1.0f)) throw Error("city options", "tree spacing must exceed 1 m");
  if (o.trees && !(o.park_share >= 0.0f && o.park_share <= 1.0f))
    throw Error("city options", "park share must be in [0, 1]");
  if (o.trees && (o.tree_leaves < 1 || o.tree_leaves > 100000))
    throw Error("city options", "tree leaves must be in [1, 100000]");
}

// The ground: one grid over the ground rectangle whose lines are the rectangle's edges plus, with a hill, a
// regular grid over the hill's square (cells about radius / 24), or with a ground function a regular grid over the
// whole rectangle (cells of ground_cell, at most 1024 a side). One tensor grid keeps every vertex shared, so the
// flat part and the hill meet without T-junctions.
scene::Mesh groundMesh(const Box2& ground, const Ground& g, float cell) {
  std::vector<float> xs{ground.lo.x}, ys{ground.lo.y};
  const Hill& hill = g.hill();
  if (g.custom()) {
    const Vec2 e = ground.extent();
    const int nx = std::clamp(int(std::ceil(e.x / cell)), 1, 1024);
    const int ny = std::clamp(int(std::ceil(e.y / cell)), 1, 1024);
    for (int i = 1; i < nx; ++i) xs.push_back(ground.lo.x + e.x * float(i) / float(nx));
    for (int j = 1; j < ny; ++j) ys.push_back(ground.lo.y + e.y * float(j) / float(ny));
  } else if (!g.flat() && hill.radius > 0.0f) {
    const int cells = 48;
    for (int i = 0; i <= cells; ++i) {
      const float t = -1.0f + 2.0f * float(i) / float(cells);
      const float x = hill.centre.x + t * hill.radius, y = hill.centre.y + t * hill.radius;
      if (x > xs.back() && x < ground.hi.x) xs.push_back(x);
      if (y > ys.back() && y < ground.hi.y) ys.push_back(y);
    }
  }
  xs.push_back(ground.hi.x);
  ys.push_back(ground.hi.y);
  scene::Mesh m;
  const size_t nx = xs.size(), ny = ys.size();
  m.positions.reserve(nx * ny);
  m.normals.reserve(nx * ny);
  m.uvs.reserve(nx * ny);
  for (size_t j = 0; j < ny; ++j)
    for (size_t i = 0; i < nx; ++i) {
      const Vec2 p(xs[i], ys[j]);
      m.positions.push_back(Vec3(p, g.height(p)));
      m.normals.push_back(g.normal(p));
      // Relative to the ground's corner: uvs stay small numbers (precise) across a city of 20 km.
      m.uvs.push_back(Vec2((p.x - ground.lo.x) / kGroundTile, -(p.y - ground.lo.y) / kGroundTile));
    }
  m.indices.reserve((nx - 1) * (ny - 1) * 6);
  for (size_t j = 0; j + 1 < ny; ++j)
    for (size_t i = 0; i + 1 < nx; ++i) {
      const uint32_t a = uint32_t(j * nx + i), b = a + 1, c = a + uint32_t(nx), d = c + 1;
      m.indices.insert(m.indices.end(), {a, b, d, a, d, c});  // counter-clockwise seen from above
    }
  return m;
}

// A mesh with exactly the memory it needs, copied from a scratch mesh whose capacity is reused.
scene::Mesh exactCopy(const scene::Mesh& m) {
  scene::Mesh out;
  out.positions.assign(m.positions.begin(), m.positions.end());
  out.normals.assign(m.normals.begin(), m.normals.end());
  out.uvs.assign(m.uvs.begin(), m.uvs.end());
  out.indices.assign(m.indices.begin(), m.indices.end());
  return out;  // Scene::addMesh computes the bounds
}

// One future scene object, built by a worker thread.
struct ObjectDraft {
  std::string name;
  Polygon2 footprint;
  scene::Mesh facades, roofs, landmark;
};

struct BlockResult {
  std::vector<ObjectDraft> objects;
  size_t buildings = 0;
  size_t skipped_lots = 0;
  int facade_material = 0;  // which facade tint
};

struct BlockJob {
  uint32_t face = 0;
  const Polygon2* footprint = nullptr;
  float height_scale = 1.0f;
  std::optional<Building> landmark;  // replaces the ordinary buildings
  bool park = false;                 // trees instead of buildings (CityOptions::trees)
};

void buildBlock(const CityOptions& options, const Ground& ground, const BlockJob& job, BlockResult& result,
                BuildingMeshes& scratch) {
  const uint64_t seed = mixSeed(options.seed, job.face);
  Rng rng(mixSeed(seed, 0xb10c));
  result.facade_material = rng.uniformInt(0, 2);
  if (job.park) return;

  std::vector<Building> buildings;
  if (job.landmark) {
    buildings.push_back(*job.landmark);
  } else {
    LotOptions lots;
    lots.height_scale = job.height_scale;
    BlockLayout layout = layoutBlock(*job.footprint, seed, lots);
    result.skipped_lots = size_t(layout.skipped_lots);
    buildings = std::move(layout.buildings);
  }
  for (Building& b : buildings) {
    if (ground.flat()) continue;
    // Stand on the lowest ground under the footprint (corners and edge midpoints), reaching a little below it,
    // and keep the building's height above the highest ground: on a slope it gains the floors it sinks by.
    float lowest = ground.height(b.footprint[0]), highest = lowest;
    for (size_t i = 0; i < b.footprint.size(); ++i) {
      const Vec2 a = b.footprint[i], c = b.footprint[(i + 1) % b.footprint.size()];
      for (float h : {ground.height(a), ground.height(0.5f * (a + c))}) {
        lowest = std::min(lowest, h);
        highest = std::max(highest, h);
      }
    }
    b.base_z = lowest - kBaseBelowGround;
    const float sunk = std::ceil((highest - b.base_z) / b.floor_height) * b.floor_height;
    b.height += sunk;
    b.top += sunk;
  }
  result.buildings = buildings.size();

  const std::string block_name = "block " + std::to_string(job.face);
  auto take = [&](ObjectDraft& draft) {
    draft.facades = exactCopy(scratch.facades);
    draft.roofs = exactCopy(scratch.roofs);
    draft.landmark = exactCopy(scratch.landmark);
  };
  if (options.objects == ObjectGrouping::Blocks) {
    scratch.clear();
    for (const Building& b : buildings) appendBuildingGeometry(b, options.detail, scratch);
    ObjectDraft draft;
    draft.name = block_name;
    draft.footprint = *job.footprint;
    take(draft);
    result.objects.push_back(std::move(draft));
  } else {
    for (size_t i = 0; i < buildings.size(); ++i) {
      scratch.clear();
      appendBuildingGeometry(buildings[i], options.detail, scratch);
      ObjectDraft draft;
      draft.name = job.landmark ? block_name + (job.landmark->landmark == LandmarkKind::Church ? " church" : " tower")
                                : block_name + " building " + std::to_string(i);
      draft.footprint = buildings[i].footprint;
      take(draft);
      result.objects.push_back(std::move(draft));
    }
  }
}

// Landmarks: a church on the block nearest the centre (on the hilltop when there is a hill), then towers and
// more churches spread over the city, at least `spacing` apart. Returns (block index, building) pairs.
std::vector<std::pair<size_t, Building>> chooseLandmarks(const std::vector<BlockFootprint>& blocks, const Box2& bounds,
                                                         uint64_t seed) {
  std::vector<std::pair<size_t, Building>> chosen;
  if (blocks.empty()) return chosen;
  const size_t n = blocks.size();
  const size_t churches = 1 + n / 500, towers = 1 + n / 150;
  const Vec2 e = bounds.extent();
  const float spacing = 0.6f * std::sqrt(std::max(1.0f, e.x * e.y) / float(churches + towers));
  std::vector<Vec2> centres(n);
  for (size_t i = 0; i < n; ++i) centres[i] = polygonCentroid(blocks[i].footprint);

  auto farEnough = [&](size_t i) {
    for (const auto& c : chosen)
      if (glm::length(centres[c.first] - centres[i]) < spacing) return false;
    return true;
  };
  auto tryPlace = [&](size_t i, LandmarkKind kind) {
    if (!farEnough(i)) return false;
    std::optional<Building> b = makeLandmark(kind, blocks[i].footprint, mixSeed(seed, 0x1a7d00 + blocks[i].face));
    if (!b) return false;
    chosen.emplace_back(i, std::move(*b));
    return true;
  };

  // The central church: blocks by distance to the centre, the first that can hold it.
  std::vector<size_t> order(n);
  for (size_t i = 0; i < n; ++i) order[i] = i;
  const Vec2 centre = bounds.center();
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    const float da = glm::length(centres[a] - centre), db = glm::length(centres[b] - centre);
    return da < db || (da == db && a < b);
  });
  for (size_t k = 0; k < std::min<size_t>(n, 64); ++k)
    if (tryPlace(order[k], LandmarkKind::Church)) break;

  // The others: blocks in a seeded random order.
  Rng rng(mixSeed(seed, 0x1a7d));
  for (size_t i = n; i > 1; --i) std::swap(order[i - 1], order[size_t(rng.next() % i)]);
  size_t placed_towers = 0, placed_churches = chosen.size();
  for (size_t k = 0; k < n && (placed_towers < towers || placed_churches < churches); ++k) {
    const LandmarkKind kind = placed_towers < towers ? LandmarkKind::Tower : LandmarkKind::Church;
    if (tryPlace(order[k], kind)) ++(kind == LandmarkKind::Tower ? placed_towers : placed_churches);
  }
  return chosen;
}

}  // namespace

float cityGroundHeight(const CityOptions& options, const Box2& city_bounds, Vec2 p) {
  if (options.ground) return options.ground(p - city_bounds.center());
  if (!options.hill) return 0.0f;
  return hillHeight(hillFor(city_bounds), p);
}

std::string streetsPathFor(const std::string& glb_path) {
  for (const std::string ext : {".glb", ".gltf"}) {
    if (glb_path.size() <= ext.size()) continue;
    std::string tail = glb_path.substr(glb_path.size() - ext.size());
    std::transform(tail.begin(), tail.end(), tail.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    if (tail == ext) return glb_path.substr(0, glb_path.size() - ext.size()) + ".streets.json";
  }
  return glb_path + ".streets.json";
}

// Street trees along every buildable block and scattered trees in the park blocks, after the blocks' objects.
static void addCityTrees(const CityOptions& options, const Ground& g, const std::vector<BlockFootprint>& blocks,
                  const std::vector<BlockJob>& jobs, City& city) {
  const VegetationMaterials materials = addVegetationMaterials(city.scene);
  TreeOptions tree;
  tree.leaves = options.tree_leaves;
  auto ground = [&](Vec2 p) { return g.height(p); };
  for (size_t i = 0; i < blocks.size(); ++i) {
    std::vector<Vec2> sites = streetTreeSites(std::span(&blocks[i].footprint, 1), options.tree_spacing, 2.0f);
    if (jobs[i].park) {
      ++city.parks;
      const std::vector<Vec2> park =
          parkTreeSites(blocks[i].footprint, 1.0f / 120.0f, 5.0f, 3.0f, mixSeed(options.seed, blocks[i].face));
      sites.insert(sites.end(), park.begin(), park.end());
    }
    const std::vector<uint32_t> ids =
        addTrees(city.scene, sites, ground, tree, mixSeed(options.seed, 0x7e3e0000ull + blocks[i].face), materials);
    city.trees += ids.size();
    city.object_block.insert(city.object_block.end(), ids.size(), int32_t(blocks[i].face));
  }
  city.scene.updateBounds();
}

City generateCity(const CityOptions& options) {
  validate(options);
  City city;
  StreetNetworkOptions net;
  net.blocks = options.blocks;
  net.seed = options.seed;
  city.streets = generateStreetNetwork(net);
  city.bounds = city.streets.bounds();
  const Ground terrain(options, city.bounds);

  const std::vector<BlockFootprint> blocks = buildableBlocks(city.streets);
  city.skipped_blocks = city.streets.blockCount() - std::min(city.streets.blockCount(), blocks.size());

  // Jobs: one per buildable block; the centre is denser and taller (height_scale up to 1.3).
  std::vector<BlockJob> jobs(blocks.size());
  const Vec2 centre = city.bounds.center();
  const float downtown = std::max(1.0f, 0.25f * glm::length(city.bounds.extent()));
  for (size_t i = 0; i < blocks.size(); ++i) {
    jobs[i].face = blocks[i].face;
    jobs[i].footprint = &blocks[i].footprint;
    const float d = glm::length(polygonCentroid(blocks[i].footprint) - centre) / downtown;
    jobs[i].height_scale = 1.0f + 0.3f * std::exp(-d * d);
  }
  for (auto& [index, building] : chooseLandmarks(blocks, city.bounds, options.seed)) {
    jobs[index].landmark = std::move(building);
    ++city.landmarks;
  }
  if (options.trees)
    for (BlockJob& job : jobs)
      job.park = !job.landmark && Rng(mixSeed(options.seed, 0x9a4c0000ull + job.face)).uniform() < options.park_share;

  // Blocks are independent (each has its own seed), so workers build them in any order; the scene is assembled
  // in block order afterwards, so the result does not depend on the thread count.
  std::vector<BlockResult> results(jobs.size());
  std::unique_ptr<Progress> progress;
  if (options.blocks >= kProgressFromBlocks) progress = std::make_unique<Progress>("gen city", jobs.size());
  std::atomic<size_t> next{0};
  auto work = [&]() {
    BuildingMeshes scratch;
    for (size_t i = next.fetch_add(1); i < jobs.size(); i = next.fetch_add(1)) {
      buildBlock(options, terrain, jobs[i], results[i], scratch);
      if (progress) progress->advance();
    }
  };
  const unsigned threads = std::clamp(std::thread::hardware_concurrency(), 1u, 16u);
  if (threads == 1 || jobs.size() < 64) {
    work();
  } else {
    std::vector<std::thread> pool;
    for (unsigned t = 0; t < threads; ++t) pool.emplace_back(work);
    for (std::thread& t : pool) t.join();
  }
  if (progress) progress->finish();

  // Materials.
  scene::Scene& scene = city.scene;
  const CityMaterials palette = addCityMaterials(scene);
  const uint32_t ground_material = palette.ground;
  const uint32_t* facade_materials = palette.facades;
  const uint32_t roof_material = palette.roof;
  const uint32_t landmark_material = palette.landmark;

  // Object 1: the ground.
  Box2 ground = city.bounds;
  ground.lo -= Vec2(kGroundMargin);
  ground.hi += Vec2(kGroundMargin);
  {
    scene::Object o;
    o.name = "ground";
    o.parts.push_back({scene.addMesh(groundMesh(ground, terrain, options.ground_cell)), ground_material});
    o.footprint = {ground.lo, Vec2(ground.hi.x, ground.lo.y), ground.hi, Vec2(ground.lo.x, ground.hi.y)};
    scene.addObject(std::move(o));
    city.object_block.push_back(-1);
  }

  size_t object_count = 1, mesh_count = 1;
  for (const BlockResult& r : results) {
    object_count += r.objects.size();
    mesh_count += 3 * r.objects.size();
  }
  scene.objects.reserve(object_count);
  scene.meshes.reserve(mesh_count);
  city.object_block.reserve(object_count);
  for (size_t i = 0; i < results.size(); ++i) {
    BlockResult& r = results[i];
    city.buildings += r.buildings;
    city.skipped_lots += r.skipped_lots;
    if (r.buildings == 0) ++city.skipped_blocks;
    for (ObjectDraft& d : r.objects) {
      scene::Object o;
      o.name = std::move(d.name);
      o.footprint = std::move(d.footprint);
      if (!d.facades.indices.empty())
        o.parts.push_back({scene.addMesh(std::move(d.facades)), facade_materials[r.facade_material]});
      if (!d.roofs.indices.empty()) o.parts.push_back({scene.addMesh(std::move(d.roofs)), roof_material});
      if (!d.landmark.indices.empty()) o.parts.push_back({scene.addMesh(std::move(d.landmark)), landmark_material});
      if (o.parts.empty()) continue;
      scene.addObject(std::move(o));
      city.object_block.push_back(int32_t(jobs[i].face));
    }
    r.objects.clear();
    r.objects.shrink_to_fit();
  }
  if (options.trees) addCityTrees(options, terrain, blocks, jobs, city);
  return city;
}

}  // namespace farfield::gen
