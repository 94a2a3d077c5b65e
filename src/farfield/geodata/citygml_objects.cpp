// The scene objects: every root object's polygons triangulated, the streets from the centre lines of the roads, and
// the objects one per root object or grouped by the street block that holds them.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <citygml/cityobject.h>

#include "farfield/core/polygon2d.h"
#include "farfield/core/progress.h"
#include "farfield/core/timer.h"
#include "farfield/geodata/citygml_importer.h"
#include "farfield/geodata/road_centrelines.h"

namespace farfield::geodata::citygml_import {

namespace {

bool isTransportation(const std::string& type) {
  return type == "Road" || type == "Railway" || type == "Square" || type == "Track" || type == "TransportationObject";
}

}  // namespace

void Importer::build() {
  scene::Scene& scene = result_.city.scene;
  CityMaterials materials(scene);
  materials_ = &materials;
  std::vector<Built> built;
  built.reserve(units_.size());
  std::vector<std::vector<std::vector<DVec2>>> road_plan;
  Progress progress("import " + source_, units_.size());
  for (const Unit& u : units_) {
    progress.advance();
    Built b{&u, {}, {}};
    const bool road = isTransportation(u.type);
    const size_t plan_before = road_plan.size();
    for (const Surface& s : u.surfaces) face(s, b.meshes, b.hull, road ? &road_plan : nullptr);
    if (road && road_plan.size() > plan_before) ++st_.road_objects;
    bool empty = true;
    for (const auto& [m, mesh] : b.meshes) empty &= mesh.indices.empty();
    if (empty) {
      skip(kNoGeometry);
      continue;
    }
    ++st_.objects_by_type[u.type];
    ++st_.lods[*u.lod];
    st_.building_parts += u.parts;
    switch (u.category) {
      case CityCategory::Building:
      case CityCategory::BuildingPart: ++st_.buildings; break;  // a part without its building stands for one
      case CityCategory::Ground: ++st_.ground_objects; break;
      case CityCategory::Other: ++st_.other_objects; break;
    }
    built.push_back(std::move(b));
  }
  progress.finish();
  if (built.empty()) throw noSurface();
  result_.file_min = used_min_;
  result_.file_max = used_max_;
  st_.road_polygons = road_plan.size();

  Stopwatch clock;
  urban::StreetGraph& graph = result_.city.streets;
  if (!road_plan.empty()) {
    RoadCentreLineStats cl;
    const std::vector<StreetPolyline> lines = roadCentreLines(road_plan, &cl);
    st_.centre_line_segments = lines.size();
    if (cl.invalid_polygons > 0) st_.skipped["road surfaces not simple (no centre lines)"] += cl.invalid_polygons;
    if (cl.degenerate_areas > 0)
      st_.skipped["united road areas without area after cleaning (no centre lines)"] += cl.degenerate_areas;
    if (!lines.empty()) graph = planarizeStreets(lines, options_.planarize, &st_.streets, source_);
  }
  st_.streets_s = clock.seconds();
  if (graph.streetCount() == 0)
    perObject(built);
  else
    byBlock(built);
  scene.updateBounds();
  result_.city.buildings = st_.buildings;
  Box2 b;
  for (const scene::Object& o : scene.objects) {
    b.expand(Vec2(o.world_bounds.lo));
    b.expand(Vec2(o.world_bounds.hi));
  }
  result_.city.bounds = graph.streetCount() > 0 ? graph.bounds() : b;
}

void Importer::addParts(scene::Scene& scene, std::map<uint32_t, scene::Mesh>& meshes, scene::Object& o) {
  for (auto& [material, mesh] : meshes)
    if (!mesh.indices.empty()) o.parts.push_back({scene.addMesh(std::move(mesh)), material});
}

// No streets: one scene object per root city object, as the CityJSON importer makes.
void Importer::perObject(std::vector<Built>& built) {
  scene::Scene& scene = result_.city.scene;
  for (Built& b : built) {
    scene::Object o;
    o.name = b.unit->object->getId();
    addParts(scene, b.meshes, o);
    o.footprint = convexHull(b.hull);
    scene.addObject(std::move(o));
    result_.city.object_block.push_back(-1);
  }
}

// Streets: object 1 is the ground (transportation and every other ground object), then buildings and other
// objects grouped by the block holding their centroid (or one object each), as importOsm groups buildings.
void Importer::byBlock(std::vector<Built>& built) {
  scene::Scene& scene = result_.city.scene;
  const urban::StreetGraph& graph = result_.city.streets;
  const bool by_block = options_.objects == gen::ObjectGrouping::Blocks;
  scene::Object ground;
  ground.name = "ground";
  std::map<uint32_t, scene::Mesh> ground_meshes;
  std::vector<Vec2> ground_hull;
  std::vector<Polygon2> blocks(graph.faceCount());
  std::vector<Box2> block_boxes(graph.faceCount());
  std::vector<double> block_areas(graph.faceCount(), 0.0);
  for (uint32_t f = 1; f < graph.faceCount(); ++f) {
    blocks[f] = graph.facePolygon(f);
    block_boxes[f] = polygonBounds(blocks[f]);
    block_areas[f] = std::abs(signedArea(blocks[f]));
  }
  auto block_of = [&](const Vec2& p) {  // the smallest block holding p (blocks may nest)
    int32_t best = -1;
    for (uint32_t f = 1; f < graph.faceCount(); ++f) {
      if (!block_boxes[f].contains(p) || (best >= 0 && block_areas[f] >= block_areas[size_t(best)])) continue;
      if (pointInPolygon(p, blocks[f])) best = int32_t(f);
    }
    return best;
  };
  // Groups in a fixed order: blocks ascending, then the outside tiles, then (buildings mode) objects in file order.
  std::map<int64_t, std::vector<size_t>> groups;
  std::map<std::pair<int, int>, int64_t> tiles;
  std::map<int64_t, int32_t> group_block;
  int64_t next_tile = -1;
  for (size_t i = 0; i < built.size(); ++i) {
    Built& b = built[i];
    if (b.unit->category == CityCategory::Ground) {
      for (auto& [m, mesh] : b.meshes) ground_meshes[m].append(mesh);
      ground_hull.insert(ground_hull.end(), b.hull.begin(), b.hull.end());
      continue;
    }
    const Polygon2 hull = convexHull(b.hull);
    const Vec2 c = hull.size() >= 3 ? polygonCentroid(hull) : (hull.empty() ? Vec2(0.0f) : hull[0]);
    const int32_t block = block_of(c);
    if (block < 0 && b.unit->category != CityCategory::Other) ++st_.outside_blocks;
    int64_t group;
    if (!by_block) {
      group = int64_t(graph.faceCount() + i);
    } else if (block >= 0) {
      group = block;
    } else {
      const std::pair<int, int> key(int(std::floor(c.x / options_.outside_tile)),
                                    int(std::floor(c.y / options_.outside_tile)));
      auto [pos, inserted] = tiles.emplace(key, next_tile);
      if (inserted) --next_tile;
      group = pos->second;
    }
    groups[group].push_back(i);
    group_block[group] = block;
  }
  addParts(scene, ground_meshes, ground);
  if (!ground.parts.empty()) {
    ground.footprint = convexHull(ground_hull);
    scene.addObject(std::move(ground));
    result_.city.object_block.push_back(-1);
  }
  std::vector<int64_t> order;
  for (const auto& [g, list] : groups)
    if (g >= 0) order.push_back(g);
  for (const auto& [g, list] : groups)
    if (g < 0) order.push_back(g);
  for (int64_t g : order) {
    const std::vector<size_t>& list = groups[g];
    scene::Object o;
    std::map<uint32_t, scene::Mesh> meshes;
    std::vector<Vec2> hull;
    for (size_t i : list) {
      for (auto& [m, mesh] : built[i].meshes) meshes[m].append(mesh);
      hull.insert(hull.end(), built[i].hull.begin(), built[i].hull.end());
    }
    if (!by_block) {
      o.name = built[list[0]].unit->object->getId();
      o.footprint = convexHull(hull);
    } else if (g > 0) {
      o.name = "block " + std::to_string(g);
      o.footprint = cleanPolygon(blocks[size_t(g)], 1e-3f);
    } else {
      o.name = "outside blocks " + std::to_string(-g - 1);
      o.footprint = convexHull(hull);
    }
    addParts(scene, meshes, o);
    scene.addObject(std::move(o));
    result_.city.object_block.push_back(group_block[g]);
  }
}

}  // namespace farfield::geodata::citygml_import
