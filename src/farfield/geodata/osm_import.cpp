// OpenStreetMap city import: read (osm_reader), project (projection), check and extrude each footprint (extrude),
// planarise the highways into the street graph (planarize) and group the buildings into scene objects by block
// (the face of the street graph holding the footprint's centroid, Sillion 1997's block = local model unit) or one
// object per building (Jeschke 2005's objects).
#include "farfield/geodata/osm_import.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <unordered_map>

#include "farfield/core/error.h"
#include "farfield/core/log.h"
#include "farfield/core/polygon2d.h"
#include "farfield/core/progress.h"
#include "farfield/core/timer.h"
#include "farfield/gen/textures.h"
#include "farfield/geodata/extrude.h"

namespace farfield::geodata {

namespace {

constexpr float kGroundMargin = 40.0f;  // the ground reaches this far beyond the data (as gen/city.cpp)
constexpr float kGroundTile = 8.0f;     // metres per asphalt texture repeat
constexpr float kStreetLift = 0.05f;    // street ribbons lie this far above the ground plane
constexpr const char* kZeroArea = "zero or tiny area";
constexpr const char* kSelfIntersecting = "self-intersecting footprint";
constexpr const char* kProjectionFailed = "projection failed";

struct Item {
  size_t source = 0;  // index into OsmData::buildings
  bool is_part = false;
  std::vector<FootprintPolygon> polygons;
  Vec2 centroid{0.0f};
  Box2 box;
  double area = 0.0;   // of the largest outer ring
  size_t largest = 0;  // index of the polygon with the largest outer ring
  ExtrusionShape shape;
  int32_t outline = -1;  // parts: the outline item they stand in
  bool replaced = false; // outlines: parts stand in it, its own volume is not drawn
  int64_t group = -1;
};

// Projects and checks one ring; nullptr when usable, else the skip reason.
const char* projectRing(const std::vector<DVec2>& lonlat, const LocalProjection& proj, float min_area,
                        Polygon2& out) {
  out.clear();
  out.reserve(lonlat.size());
  for (const DVec2& p : lonlat) {
    const DVec2 q = proj.toLocal(p.x, p.y);
    if (!std::isfinite(q.x) || !std::isfinite(q.y)) return kProjectionFailed;
    out.emplace_back(float(q.x), float(q.y));
  }
  out = cleanPolygon(out, 1e-3f);
  if (out.size() < 3 || std::abs(signedArea(out)) < double(min_area)) return kZeroArea;
  if (!isSimplePolygon(out)) return kSelfIntersecting;
  return nullptr;
}

RoofKind roofKind(const std::string& shape) {
  if (shape.empty() || shape == "flat") return RoofKind::Flat;
  if (shape == "gabled" || shape == "saltbox" || shape == "gambrel") return RoofKind::Gabled;
  return RoofKind::Pyramidal;  // pyramidal, hipped, half-hipped, dome, onion, ...: approximated by a pyramid
}

// Uniform grid of boxes for point queries ("which polygons may hold p").
class BoxGrid {
 public:
  void build(const std::vector<Box2>& boxes, float cell) {
    cell_ = cell;
    Box2 all;
    for (const Box2& b : boxes) all.expand(b);
    if (all.empty()) return;
    // At most a few cells per box and ~4 million in all, whatever the extent (a whole region's extract, or two
    // buildings far apart: a grid of millions of empty cells for them took seconds to build and free).
    const double max_cells = std::clamp(4.0 * double(boxes.size()), 1024.0, 4.0e6);
    while ((double(all.extent().x) / cell_ + 1.0) * (double(all.extent().y) / cell_ + 1.0) > max_cells) cell_ *= 2.0f;
    cell = cell_;
    lo_ = all.lo;
    nx_ = std::max(1, int(std::ceil(all.extent().x / cell)) + 1);
    ny_ = std::max(1, int(std::ceil(all.extent().y / cell)) + 1);
    cells_.assign(size_t(nx_) * ny_, {});
    for (uint32_t i = 0; i < boxes.size(); ++i) {
      if (boxes[i].empty()) continue;
      const int x0 = cx(boxes[i].lo.x), x1 = cx(boxes[i].hi.x), y0 = cy(boxes[i].lo.y), y1 = cy(boxes[i].hi.y);
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) cells_[size_t(y) * nx_ + x].push_back(i);
    }
  }
  const std::vector<uint32_t>& at(const Vec2& p) const {
    static const std::vector<uint32_t> kEmpty;
    if (cells_.empty()) return kEmpty;
    const float fx = (p.x - lo_.x) / cell_, fy = (p.y - lo_.y) / cell_;
    if (!(fx >= 0.0f) || !(fy >= 0.0f) || fx >= float(nx_) || fy >= float(ny_)) return kEmpty;
    return cells_[size_t(int(fy)) * nx_ + size_t(int(fx))];
  }

 private:
  int cx(float x) const { return std::clamp(int((x - lo_.x) / cell_), 0, nx_ - 1); }
  int cy(float y) const { return std::clamp(int((y - lo_.y) / cell_), 0, ny_ - 1); }
  Vec2 lo_{0.0f};
  float cell_ = 100.0f;
  int nx_ = 0, ny_ = 0;
  std::vector<std::vector<uint32_t>> cells_;
};

uint32_t hashTint(uint64_t key) {
  key ^= key >> 33;
  key *= 0xff51afd7ed558ccdull;
  key ^= key >> 33;
  return uint32_t(key % 3);
}

void appendStreetRibbons(const urban::StreetGraph& g, scene::Mesh& m) {
  for (const urban::Street& s : g.streets()) {
    const Vec2 a = g.position(s.a), b = g.position(s.b);
    const Vec2 d = b - a;
    const float len = glm::length(d);
    if (!(len > 0.0f)) continue;
    const Vec2 dir = d / len, side(-dir.y, dir.x);
    const float h = 0.5f * s.width;
    // Extended by half the width at both ends so that junctions are covered.
    const Vec2 p0 = a - dir * h, p1 = b + dir * h;
    const Vec2 corners[4] = {p0 - side * h, p1 - side * h, p1 + side * h, p0 + side * h};
    const uint32_t first = uint32_t(m.positions.size());
    for (const Vec2& c : corners) {
      m.positions.emplace_back(c, kStreetLift);
      m.normals.emplace_back(0.0f, 0.0f, 1.0f);
      m.uvs.emplace_back(c.x / kGroundTile, -c.y / kGroundTile);
    }
    m.indices.insert(m.indices.end(), {first, first + 1, first + 2, first, first + 2, first + 3});
  }
}

}  // namespace

size_t OsmImportStats::skippedTotal() const {
  size_t n = 0;
  for (const auto& [reason, count] : skipped) n += count;
  return n;
}

std::vector<std::string> parseHighwayList(const std::string& option, const std::string& text) {
  std::vector<std::string> out;
  size_t start = 0;
  while (start <= text.size()) {
    const size_t comma = text.find(',', start);
    std::string item = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    item.erase(0, item.find_first_not_of(' '));
    item.erase(item.find_last_not_of(' ') + 1);
    if (!item.empty()) {
      if (!findHighwayClass(item)) {
        std::string known;
        for (const HighwayClass& c : knownHighwayClasses()) known += (known.empty() ? "" : ", ") + c.name;
        throw Error(option, "unknown highway class '" + item + "' (known: " + known + ")");
      }
      out.push_back(item);
    }
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (out.empty()) throw Error(option, "expected a comma-separated list of highway classes");
  return out;
}

OsmCity importOsm(const std::string& path, const OsmImportOptions& options) {
  OsmCity result;
  OsmImportStats& st = result.stats;
  Stopwatch clock;

  OsmData data = readOsm(path, options.read);
  st.read_s = clock.seconds();
  st.skipped = data.skipped;
  st.highway_ways = data.highway_ways;
  st.outside_bbox = data.outside_bbox;
  st.nodes = data.nodes;
  st.ways = data.ways;
  st.relations = data.relations;
  st.read_error = data.read_error;
  if (!data.read_error.empty())
    FF_WARN(path << ": the file ends early or is corrupt (" << data.read_error << "); importing what was read before");

  // Projection centred on the data.
  clock.restart();
  double lon0 = 1e9, lat0 = 1e9, lon1 = -1e9, lat1 = -1e9;
  auto grow = [&](const DVec2& p) {
    lon0 = std::min(lon0, p.x), lat0 = std::min(lat0, p.y);
    lon1 = std::max(lon1, p.x), lat1 = std::max(lat1, p.y);
  };
  for (const OsmBuilding& b : data.buildings)
    for (const LonLatPolygon& poly : b.polygons)
      for (const DVec2& p : poly[0]) grow(p);
  for (const OsmHighway& h : data.highways)
    for (const DVec2& p : h.points) grow(p);
  if (options.read.bbox) {
    lon0 = options.read.bbox->min_lon, lat0 = options.read.bbox->min_lat;
    lon1 = options.read.bbox->max_lon, lat1 = options.read.bbox->max_lat;
  }
  LocalProjection projection(0.5 * (lon0 + lon1), 0.5 * (lat0 + lat1));
  result.reference = projection.reference();

  // Footprints: projected, cleaned, checked.
  std::vector<Item> items;
  items.reserve(data.buildings.size());
  {
    Polygon2 ring;
    for (size_t bi = 0; bi < data.buildings.size(); ++bi) {
      const OsmBuilding& b = data.buildings[bi];
      Item item;
      item.source = bi;
      item.is_part = b.is_part;
      const char* first_reason = nullptr;
      for (const LonLatPolygon& poly : b.polygons) {
        const char* reason = projectRing(poly[0], projection, options.min_footprint_area, ring);
        if (reason) {
          if (!first_reason) first_reason = reason;
          ++st.dropped_rings;
          continue;
        }
        FootprintPolygon fp;
        fp.outer = ring;
        makeCounterClockwise(fp.outer);
        for (size_t h = 1; h < poly.size(); ++h) {
          if (projectRing(poly[h], projection, 0.01f, ring)) {
            ++st.dropped_rings;
            continue;
          }
          fp.holes.push_back(ring);
        }
        item.polygons.push_back(std::move(fp));
      }
      if (item.polygons.empty()) {
        st.dropped_rings -= b.polygons.size();  // the whole building is the skip, not its rings
        ++st.skipped[first_reason ? first_reason : kZeroArea];
        continue;
      }
      for (size_t k = 0; k < item.polygons.size(); ++k) {
        const double a = std::abs(signedArea(item.polygons[k].outer));
        if (a > item.area) item.area = a, item.largest = k;
        item.box.expand(polygonBounds(item.polygons[k].outer));
      }
      item.centroid = polygonCentroid(item.polygons[item.largest].outer);
      item.shape.base = float(b.height.base);
      item.shape.top = float(b.height.top);
      item.shape.roof = roofKind(b.roof_shape);
      item.shape.roof_height = float(b.roof_height);
      if (b.height.bad_value) ++st.bad_height_tags;
      items.push_back(std::move(item));
    }
  }

  // Parts replace the outline they stand in (OSM Simple 3D Buildings).
  {
    std::vector<Box2> boxes(items.size());
    for (size_t i = 0; i < items.size(); ++i)
      if (!items[i].is_part) boxes[i] = items[i].box;
    BoxGrid grid;
    grid.build(boxes, 100.0f);
    for (size_t i = 0; i < items.size(); ++i) {
      if (!items[i].is_part) continue;
      const Vec2 c = items[i].centroid;
      int32_t best = -1;
      for (uint32_t k : grid.at(c)) {
        const Item& o = items[k];
        if (o.is_part || !o.box.contains(c)) continue;
        bool inside = false;
        for (const FootprintPolygon& fp : o.polygons)
          if (pointInPolygon(c, fp.outer)) inside = true;
        if (inside && (best < 0 || o.area < items[size_t(best)].area)) best = int32_t(k);
      }
      items[i].outline = best;
      if (best >= 0) items[size_t(best)].replaced = true;
    }
  }
  st.build_s = clock.seconds();

  // Street graph.
  clock.restart();
  {
    std::vector<StreetPolyline> lines;
    lines.reserve(data.highways.size());
    for (const OsmHighway& h : data.highways) {
      StreetPolyline line;
      line.width = h.width;
      line.street_class = h.street_class;
      for (const DVec2& p : h.points) {
        const DVec2 q = projection.toLocal(p.x, p.y);
        if (std::isfinite(q.x) && std::isfinite(q.y)) line.points.push_back(q);
      }
      if (line.points.size() >= 2) lines.push_back(std::move(line));
    }
    result.city.streets = planarizeStreets(lines, options.planarize, &st.streets, path);
  }
  st.streets_s = clock.seconds();

  // Blocks: the bounded face holding each building's centroid (the smallest, for faces nested in others).
  clock.restart();
  const urban::StreetGraph& graph = result.city.streets;
  std::vector<Polygon2> block_polygons(graph.faceCount());
  std::vector<double> block_areas(graph.faceCount(), 0.0);
  std::unordered_map<int64_t, int32_t> group_block;  // object group -> block (-1: none)
  {
    std::vector<Box2> boxes(graph.faceCount());
    for (uint32_t f = 1; f < graph.faceCount(); ++f) {
      block_polygons[f] = graph.facePolygon(f);
      block_areas[f] = std::abs(signedArea(block_polygons[f]));
      boxes[f] = polygonBounds(block_polygons[f]);
    }
    BoxGrid grid;
    grid.build(boxes, 100.0f);
    auto block_of = [&](const Vec2& p) {
      int32_t best = -1;
      for (uint32_t f : grid.at(p)) {
        if (f == 0 || (best >= 0 && block_areas[f] >= block_areas[size_t(best)])) continue;
        if (pointInPolygon(p, block_polygons[f])) best = int32_t(f);
      }
      return best;
    };
    const bool by_block = options.objects == gen::ObjectGrouping::Blocks;
    std::map<std::pair<int, int>, int64_t> tiles;
    int64_t next_tile = -1;
    for (size_t i = 0; i < items.size(); ++i) {
      Item& it = items[i];
      if (it.is_part && it.outline >= 0) continue;  // follows its outline (below)
      const int32_t block = block_of(it.centroid);
      if (block < 0) ++st.outside_blocks;
      if (!by_block) {
        it.group = int64_t(i);
      } else if (block >= 0) {
        it.group = block;
      } else {
        // Buildings in no block: square tiles, numbered -1, -2, ... in order of appearance.
        const std::pair<int, int> key(int(std::floor(it.centroid.x / options.outside_tile)),
                                      int(std::floor(it.centroid.y / options.outside_tile)));
        auto [pos, inserted] = tiles.emplace(key, next_tile);
        if (inserted) --next_tile;
        it.group = pos->second;
      }
      group_block[it.group] = block;
    }
    for (Item& it : items)
      if (it.is_part && it.outline >= 0) it.group = items[size_t(it.outline)].group;
  }
  st.assign_s = clock.seconds();

  // Scene.
  clock.restart();
  gen::City& city = result.city;
  scene::Scene& scene = city.scene;
  const gen::CityMaterials palette = gen::addCityMaterials(scene);
  const uint32_t asphalt = palette.ground;
  const uint32_t* facade_materials = palette.facades;
  const uint32_t roof_material = palette.roof;
  scene::Material pavement_material;
  pavement_material.name = "pavement";
  pavement_material.base_color = Vec4(0.95f, 0.91f, 0.84f, 1.0f);
  pavement_material.texture = gen::cityTextures().ground;
  const uint32_t pavement = scene.addMaterial(std::move(pavement_material));

  Box2 data_box = graph.bounds();
  for (const Item& it : items) data_box.expand(it.box);
  city.bounds = graph.streetCount() > 0 ? graph.bounds() : data_box;
  if (options.ground && !data_box.empty()) {
    Box2 g = data_box;
    g.lo -= Vec2(kGroundMargin);
    g.hi += Vec2(kGroundMargin);
    scene::Mesh plane;
    const Vec2 corners[4] = {g.lo, Vec2(g.hi.x, g.lo.y), g.hi, Vec2(g.lo.x, g.hi.y)};
    for (const Vec2& c : corners) {
      plane.positions.emplace_back(c, 0.0f);
      plane.normals.emplace_back(0.0f, 0.0f, 1.0f);
      plane.uvs.emplace_back(c.x / kGroundTile, -c.y / kGroundTile);
    }
    plane.indices = {0, 1, 2, 0, 2, 3};
    scene::Object o;
    o.name = "ground";
    o.parts.push_back({scene.addMesh(std::move(plane)), pavement});
    scene::Mesh streets;
    appendStreetRibbons(graph, streets);
    if (!streets.indices.empty()) o.parts.push_back({scene.addMesh(std::move(streets)), asphalt});
    o.footprint = {corners[0], corners[1], corners[2], corners[3]};
    scene.addObject(std::move(o));
    city.object_block.push_back(-1);
  }

  // Groups in a fixed order: blocks (or buildings) ascending, then the outside tiles.
  std::map<int64_t, std::vector<size_t>> groups;
  for (size_t i = 0; i < items.size(); ++i) groups[items[i].group].push_back(i);
  std::vector<int64_t> order;
  for (const auto& [g, list] : groups)
    if (g >= 0) order.push_back(g);
  for (const auto& [g, list] : groups)
    if (g < 0) order.push_back(g);

  Progress progress("build meshes", order.size());
  const bool by_block = options.objects == gen::ObjectGrouping::Blocks;
  for (int64_t g : order) {
    const std::vector<size_t>& list = groups[g];
    scene::Mesh facades, roofs;
    std::vector<Vec2> hull_points;
    size_t drawn = 0;
    for (size_t i : list) {
      const Item& it = items[i];
      const OsmBuilding& b = data.buildings[it.source];
      it.is_part ? ++st.parts : ++st.buildings;
      if (it.replaced) ++st.outlines_replaced;
      else if (b.height.source == HeightSource::Default) ++st.default_height_used;
      for (const FootprintPolygon& fp : it.polygons) hull_points.insert(hull_points.end(), fp.outer.begin(), fp.outer.end());
      if (it.replaced) continue;
      for (const FootprintPolygon& fp : it.polygons)
        if (extrudeBuilding(fp, it.shape, facades, roofs)) ++drawn;
    }
    progress.advance();
    if (facades.indices.empty() && roofs.indices.empty()) continue;
    scene::Object o;
    const int32_t block = group_block.count(g) ? group_block[g] : -1;
    if (by_block) {
      if (g > 0) {
        o.name = "block " + std::to_string(g);
        o.footprint = cleanPolygon(block_polygons[size_t(g)], 1e-3f);  // without the spikes of dead ends
      } else {
        o.name = "outside blocks " + std::to_string(-g - 1);
        o.footprint = convexHull(hull_points);
      }
    } else {
      const Item& head = items[size_t(g)];
      const OsmBuilding& b = data.buildings[head.source];
      o.name = std::string(b.from_relation ? "relation " : "way ") + std::to_string(b.id);
      o.footprint = head.polygons[head.largest].outer;
    }
    const uint32_t tint = hashTint(uint64_t(g) * 2654435761ull + 12345u);
    if (!facades.indices.empty()) o.parts.push_back({scene.addMesh(std::move(facades)), facade_materials[tint]});
    if (!roofs.indices.empty()) o.parts.push_back({scene.addMesh(std::move(roofs)), roof_material});
    scene.addObject(std::move(o));
    city.object_block.push_back(block);
  }
  progress.finish();
  scene.updateBounds();
  city.buildings = st.buildings;
  st.build_s += clock.seconds();
  if (scene.objects.size() <= (options.ground ? 1u : 0u) && graph.streetCount() == 0)
    throw Error(path, "no usable building or street (" + std::to_string(st.skippedTotal()) +
                          " buildings skipped as malformed)");
  return result;
}

}  // namespace farfield::geodata
