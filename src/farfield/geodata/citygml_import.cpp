// CityGML import. libcitygml parses the document (Xerces-C) into city objects, geometries and polygons with their
// appearances; it is asked not to tessellate, so that every polygon is triangulated here, in its plane and with its
// holes, like CityJSON faces (its own tessellator keeps a ring's closing vertex and makes a degenerate triangle of
// it). Two passes: the first chooses each object's LoD and polygons and bounds them (the origin is the centre of
// those bounds), the second triangulates them in local coordinates. libcitygml reports a malformed document by
// throwing Xerces exceptions (not std::exception) or by returning no model: both become farfield::Error here.
#include "farfield/geodata/citygml_import.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <unordered_set>

#include <citygml/citygml.h>
#include <citygml/citygmllogger.h>
#include <citygml/citymodel.h>
#include <citygml/cityobject.h>
#include <citygml/envelope.h>
#include <citygml/geometry.h>
#include <citygml/georeferencedtexture.h>
#include <citygml/material.h>
#include <citygml/polygon.h>
#include <citygml/texture.h>
#include <citygml/texturecoordinates.h>
#include <citygml/texturetargetdefinition.h>
#include <proj.h>
#include <xercesc/sax/SAXParseException.hpp>
#include <xercesc/util/XMLException.hpp>

#include "farfield/core/error.h"
#include "farfield/core/log.h"
#include "farfield/core/polygon2d.h"
#include "farfield/core/progress.h"
#include "farfield/core/timer.h"
#include "farfield/geodata/city_surfaces.h"
#include "farfield/geodata/road_centrelines.h"

namespace farfield::geodata {

namespace {

namespace fs = std::filesystem;
using CityObjectType = citygml::CityObject::CityObjectsType;

// Skip reasons.
constexpr const char* kNoExterior = "polygons without an exterior ring";
constexpr const char* kTooFew = "polygons with fewer than 3 distinct vertices";
constexpr const char* kNoArea = "polygons without area";
constexpr const char* kBadCoordinate = "polygons with non-finite coordinates";
constexpr const char* kImplicit = "implicit geometries (templates not supported)";
constexpr const char* kNoGeometry = "objects without usable geometry";
constexpr const char* kLodFiltered = "objects without geometry at the requested LoD";

// Xerces messages are UTF-16; the ASCII part is what an error message needs.
std::string narrow(const XMLCh* s) {
  std::string out;
  for (; s && *s; ++s) out += (*s < 128) ? char(*s) : '?';
  return out;
}

// libcitygml's log: errors and warnings counted, the first error kept for the message of a failed load.
class Logger final : public citygml::CityGMLLogger {
 public:
  Logger() : CityGMLLogger(LOGLEVEL::LL_WARNING) {}
  void log(LOGLEVEL level, const std::string& message, const char*, int) const override {
    if (level == LOGLEVEL::LL_ERROR && first_error.empty()) first_error = message;
    ++count;
    FF_DEBUG("libcitygml: " << message);
  }
  mutable std::string first_error;
  mutable size_t count = 0;
};

// "2.0" or "1.0" from the CityGML namespace declared at the top of the document.
std::string versionOf(const std::string& head) {
  if (head.find("opengis.net/citygml/2.0") != std::string::npos) return "2.0";
  if (head.find("opengis.net/citygml/1.0") != std::string::npos) return "1.0";
  if (head.find("opengis.net/citygml/3.0") != std::string::npos) return "3.0";
  return "";
}

// True when PROJ reads `srs` as a geographic CRS (degrees), alone or as the horizontal part of a compound one.
bool isGeographic(const std::string& srs) {
  if (srs.empty()) return false;
  PJ_CONTEXT* ctx = proj_context_create();
  proj_log_level(ctx, PJ_LOG_NONE);
  bool geographic = false;
  if (PJ* crs = proj_create(ctx, srs.c_str())) {
    PJ_TYPE type = proj_get_type(crs);
    PJ* horizontal = nullptr;
    if (type == PJ_TYPE_COMPOUND_CRS && (horizontal = proj_crs_get_sub_crs(ctx, crs, 0))) type = proj_get_type(horizontal);
    geographic = type == PJ_TYPE_GEOGRAPHIC_2D_CRS || type == PJ_TYPE_GEOGRAPHIC_3D_CRS;
    if (horizontal) proj_destroy(horizontal);
    proj_destroy(crs);
  }
  proj_context_destroy(ctx);
  return geographic;
}

// A geometry of an object to draw, with the semantic type of the city object holding it ("RoofSurface", ...).
struct GeometryRef {
  const citygml::Geometry* geometry;
  std::string holder_type;
};

// Geometries of `o` and of its descendants that belong to it (boundary surfaces, installations, openings), and the
// BuildingParts below it, which choose their LoD on their own.
void collectGeometries(const citygml::CityObject& o, std::vector<GeometryRef>& out,
                       std::vector<const citygml::CityObject*>& parts, size_t& implicit, int depth = 0) {
  if (depth > 64) return;  // libcitygml builds a tree; a bound keeps a pathological one from exhausting the stack
  for (unsigned i = 0; i < o.getGeometriesCount(); ++i) out.push_back({&o.getGeometry(i), o.getTypeAsString()});
  implicit += o.getImplicitGeometryCount();
  for (unsigned i = 0; i < o.getChildCityObjectsCount(); ++i) {
    const citygml::CityObject& c = o.getChildCityObject(i);
    if (c.getType() == CityObjectType::COT_BuildingPart)
      parts.push_back(&c);
    else
      collectGeometries(c, out, parts, implicit, depth + 1);
  }
}

void collectPolygons(const citygml::Geometry& g, std::vector<const citygml::Polygon*>& out, int depth = 0) {
  if (depth > 64) return;
  for (unsigned i = 0; i < g.getPolygonsCount(); ++i)
    if (auto p = g.getPolygon(i)) out.push_back(p.get());
  for (unsigned i = 0; i < g.getGeometriesCount(); ++i) collectPolygons(g.getGeometry(i), out, depth + 1);
}

// A polygon chosen for a root object, with how to colour it when it has no appearance.
struct Surface {
  const citygml::Polygon* polygon;
  std::optional<SurfaceClass> semantic;
  SurfaceClass fallback;
  bool by_normal;
};

// A root city object: what it draws and what it counts as.
struct Unit {
  const citygml::CityObject* object;
  std::string type;
  CityCategory category;
  std::vector<Surface> surfaces;
  size_t parts = 0;
  std::optional<unsigned> lod;
  bool lod_filtered = false;
};

bool isTransportation(const std::string& type) {
  return type == "Road" || type == "Railway" || type == "Square" || type == "Track" || type == "TransportationObject";
}

class Importer {
 public:
  Importer(const std::string& source, const std::string& base_dir, const CityGmlImportOptions& options,
           CityGmlScene& result)
      : source_(source), base_dir_(base_dir), options_(options), result_(result), st_(result.stats),
        texture_files_(st_.import) {}

  void run(const citygml::CityModel& model) {
    Stopwatch clock;
    st_.themes = model.themes();
    if (!options_.theme.empty() && std::find(st_.themes.begin(), st_.themes.end(), options_.theme) == st_.themes.end()) {
      std::string known;
      for (const std::string& t : st_.themes) known += (known.empty() ? "" : ", ") + t;
      throw Error(source_, "no appearance theme '" + options_.theme + "' (themes: " + (known.empty() ? "none" : known) + ")");
    }
    st_.theme = !options_.theme.empty() ? options_.theme : st_.themes.empty() ? std::string() : st_.themes.front();

    const citygml::ConstCityObjects roots = model.getRootCityObjects();
    st_.city_objects = roots.size();
    for (const citygml::CityObject* o : roots) chooseSurfaces(*o);
    readCrs(model);

    // Bounds of what is drawn (exterior rings), in file coordinates; the origin is their rounded centre.
    DVec3 lo(std::numeric_limits<double>::max()), hi(std::numeric_limits<double>::lowest());
    for (const Unit& u : units_)
      for (const Surface& s : u.surfaces)
        if (const auto ring = s.polygon->exteriorRing())
          for (const TVec3d& v : ring->getVertices()) {
            const DVec3 p(v.x, v.y, v.z);
            if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) continue;
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
          }
    if (lo.x > hi.x) throw noSurface();
    origin_ = DVec3(std::round(0.5 * (lo.x + hi.x)), std::round(0.5 * (lo.y + hi.y)), 0.0);
    result_.reference.origin = origin_;
    st_.read_s += clock.seconds();
    clock.restart();

    build();
    st_.build_s = clock.seconds();
  }

 private:
  Error noSurface() const {
    std::string why;
    for (const auto& [reason, n] : st_.skipped) why += (why.empty() ? "" : ", ") + std::to_string(n) + " " + reason;
    return Error(source_, "no usable surface in " + std::to_string(st_.city_objects) + " city objects" +
                              (why.empty() ? std::string() : " (skipped: " + why + ")"));
  }

  void readCrs(const citygml::CityModel& model) {
    std::string srs = model.getEnvelope().srsName();
    if (srs.empty()) srs = model.getSRSName();
    for (size_t i = 0; srs.empty() && i < units_.size(); ++i)
      for (unsigned g = 0; srs.empty() && g < units_[i].object->getGeometriesCount(); ++g)
        srs = units_[i].object->getGeometry(g).getSRSName();
    st_.crs = srs;
    result_.reference.crs = srs.empty() ? "unknown (CityGML without srsName)" : srs;
    result_.reference.description = srs;
    if (isGeographic(srs))
      throw Error(source_, "geographic coordinates (" + srs +
                               ", degrees) are not supported: reproject the file to a projected CRS in metres first");
  }

  // Chooses a root object's LoD and polygons (its own and its BuildingParts', each at their own highest LoD).
  void chooseSurfaces(const citygml::CityObject& root) {
    Unit u;
    u.object = &root;
    u.type = root.getTypeAsString();
    u.category = cityCategoryOf(u.type);
    if (u.category == CityCategory::Ground && !options_.ground_objects) return;
    if (u.category == CityCategory::Other && !options_.other_objects) return;
    std::unordered_set<const citygml::Polygon*> seen;
    std::vector<const citygml::CityObject*> pending{&root};
    bool any_geometry = false;
    while (!pending.empty()) {
      const citygml::CityObject* o = pending.back();
      pending.pop_back();
      std::vector<GeometryRef> refs;
      std::vector<const citygml::CityObject*> parts;
      size_t implicit = 0;
      collectGeometries(*o, refs, parts, implicit);
      if (implicit) st_.skipped[kImplicit] += implicit;
      for (const citygml::CityObject* p : parts) pending.push_back(p);
      std::optional<unsigned> best;
      for (const GeometryRef& r : refs) {
        any_geometry = true;
        const unsigned lod = r.geometry->getLOD();
        if (options_.max_lod && lod > *options_.max_lod) continue;
        if (!best || lod > *best) best = lod;
      }
      if (!best) continue;
      if (!u.lod || *best > *u.lod) u.lod = best;
      const size_t before = u.surfaces.size();
      // Boundary surfaces first, so that a polygon an LoD2 solid links again keeps its semantic class.
      std::stable_sort(refs.begin(), refs.end(), [](const GeometryRef& a, const GeometryRef& b) {
        return semanticSurfaceClass(a.holder_type).has_value() > semanticSurfaceClass(b.holder_type).has_value();
      });
      const CityCategory cat = cityCategoryOf(o->getTypeAsString());
      const bool building = cat == CityCategory::Building || cat == CityCategory::BuildingPart;
      const SurfaceClass fallback = building ? kWall : defaultSurfaceClass(u.type);
      for (const GeometryRef& r : refs) {
        if (r.geometry->getLOD() != *best) continue;
        std::vector<const citygml::Polygon*> polygons;
        collectPolygons(*r.geometry, polygons);
        const std::optional<SurfaceClass> semantic = semanticSurfaceClass(r.holder_type);
        for (const citygml::Polygon* p : polygons) {
          if (!seen.insert(p).second) {
            ++st_.shared_polygons;
            continue;
          }
          u.surfaces.push_back({p, semantic, fallback, building && !semantic});
        }
      }
      if (o != &root && u.surfaces.size() > before && o->getType() == CityObjectType::COT_BuildingPart) ++u.parts;
    }
    if (u.surfaces.empty()) {
      if (any_geometry) u.lod_filtered = true;
      ++st_.skipped[any_geometry ? kLodFiltered : kNoGeometry];
      return;
    }
    units_.push_back(std::move(u));
  }

  // The ring's vertices in local coordinates without a repeated closing vertex; `closed` says whether one was
  // dropped. False for a non-finite coordinate.
  bool ringOf(const citygml::LinearRing& ring, std::vector<DVec3>& out, bool& closed) const {
    out.clear();
    for (const TVec3d& v : ring.getVertices()) {
      const DVec3 p(v.x, v.y, v.z);
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) return false;
      out.push_back(p - origin_);
    }
    closed = out.size() > 3 && out.front() == out.back();
    if (closed) out.pop_back();
    return true;
  }

  // The polygon's texture in the theme and its coordinates per kept ring; nullopt (face.uvs empty) when it has
  // none or they do not fit.
  std::optional<uint32_t> textureOf(const citygml::Polygon& p, const std::vector<const citygml::LinearRing*>& rings,
                                    const std::vector<bool>& closed, CityFace& face) {
    if (st_.theme.empty()) return std::nullopt;
    std::shared_ptr<const citygml::TextureTargetDefinition> def = p.getTextureTargetDefinitionForTheme(st_.theme, true);
    if (!def) def = p.getTextureTargetDefinitionForTheme(st_.theme, false);
    if (!def || !def->getAppearance()) return std::nullopt;
    const std::shared_ptr<const citygml::Texture> tex = def->getAppearance();
    face.uvs.assign(rings.size(), {});
    for (size_t r = 0; r < rings.size(); ++r) {
      const auto coords = def->getTextureCoordinatesForID(rings[r]->getId());
      const size_t n = face.rings[r].size();
      if (!coords || (coords->getCoords().size() != n && coords->getCoords().size() != n + (closed[r] ? 1 : 0))) {
        ++st_.bad_texture_coordinates;
        face.uvs.clear();
        return std::nullopt;
      }
      for (size_t i = 0; i < n; ++i) {
        const TVec2f& c = coords->getCoords()[i];
        // CityGML puts (0, 0) at the bottom left of the image, Farfield at the top left.
        const Vec2 uv(c.x, 1.0f - c.y);
        if (!isFinite(uv)) {
          ++st_.bad_texture_coordinates;
          face.uvs.clear();
          return std::nullopt;
        }
        face.uvs[r].push_back(uv);
      }
    }
    std::string url = tex->getUrl();
    std::replace(url.begin(), url.end(), '\\', '/');
    std::shared_ptr<const image::ColorImage> img;
    std::string file;
    if (url.empty()) {
      url = "texture " + tex->getId();
      img = texture_files_.placeholder(url, "no image URI");
    } else if (url.find("://") != std::string::npos) {
      img = texture_files_.placeholder(url, "not a local file (URLs are not fetched)");
    } else {
      const fs::path path = fs::path(url).is_absolute() ? fs::path(url) : fs::path(base_dir_) / url;
      img = texture_files_.load(url, path);
      if (!scene::TextureFiles::isPlaceholder(img)) file = path.string();
    }
    return materials_->forTexture(url, img, file);
  }

  std::optional<uint32_t> materialOf(const citygml::Polygon& p) {
    if (st_.theme.empty()) return std::nullopt;
    const std::shared_ptr<const citygml::Material> m = p.getMaterialFor(st_.theme);
    if (!m) return std::nullopt;
    const TVec3f d = m->getDiffuse();
    Vec4 rgba(d.r, d.g, d.b, 1.0f - m->getTransparency());
    if (!isFinite(Vec3(rgba)) || !std::isfinite(rgba.a)) return std::nullopt;
    rgba = glm::clamp(rgba, Vec4(0.0f), Vec4(1.0f));
    const std::string key = m->getId().empty() ? "material" : m->getId();
    return materials_->forColour("material " + key, key, rgba);
  }

  // Triangulates one surface into `meshes`; adds its outline to `hull` and, for roads, its plan to `plan`.
  void face(const Surface& s, std::map<uint32_t, scene::Mesh>& meshes, std::vector<Vec2>& hull,
            std::vector<std::vector<std::vector<DVec2>>>* plan) {
    const citygml::Polygon& p = *s.polygon;
    const auto exterior = p.exteriorRing();
    if (!exterior) return skip(kNoExterior);
    CityFace f;
    std::vector<const citygml::LinearRing*> rings;
    std::vector<bool> closed;
    std::vector<DVec3> pts;
    bool c = false;
    if (!ringOf(*exterior, pts, c)) return skip(kBadCoordinate);
    if (pts.size() < 3) return skip(kTooFew);
    f.rings.push_back(pts);
    rings.push_back(exterior.get());
    closed.push_back(c);
    for (const auto& hole : p.interiorRings()) {
      if (!hole || !ringOf(*hole, pts, c) || pts.size() < 3) continue;  // a degenerate hole is dropped
      f.rings.push_back(pts);
      rings.push_back(hole.get());
      closed.push_back(c);
    }
    PolygonTriangulation t;
    DVec3 n(0.0, 0.0, 1.0);
    if (!triangulateCityFace(f, t, &n)) return skip(kNoArea);
    SurfaceClass cls = s.fallback;
    if (s.semantic) {
      cls = *s.semantic;
      ++st_.semantic_surfaces;
    } else if (s.by_normal) {
      cls = classByNormal(p.negNormal() ? -n : n);
      ++st_.inferred_surfaces;
    }
    std::optional<uint32_t> material = textureOf(p, rings, closed, f);
    if (material) {
      ++st_.textured_surfaces;
    } else if ((material = materialOf(p))) {
      ++st_.material_surfaces;
    }
    st_.triangles += appendCityFace(f, t, n, p.negNormal(), meshes[material ? *material : materials_->forClass(cls)]);
    ++st_.surfaces;
    st_.holes += f.rings.size() - 1;
    for (const DVec3& q : f.rings[0]) {
      hull.emplace_back(float(q.x), float(q.y));
      used_min_ = glm::min(used_min_, q + origin_);
      used_max_ = glm::max(used_max_, q + origin_);
    }
    if (plan && std::abs(n.z) > 0.5) {  // road surfaces seen from above (not kerbs or walls of tunnels)
      std::vector<std::vector<DVec2>> rings2;
      for (const auto& ring : f.rings) {
        rings2.emplace_back();
        for (const DVec3& q : ring) rings2.back().emplace_back(q.x, q.y);
      }
      plan->push_back(std::move(rings2));
    }
  }

  void skip(const char* reason) { ++st_.skipped[reason]; }

  // A built root object, before it becomes a scene object (alone or in its block).
  struct Built {
    const Unit* unit;
    std::map<uint32_t, scene::Mesh> meshes;
    std::vector<Vec2> hull;
  };

  void build() {
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

  static void addParts(scene::Scene& scene, std::map<uint32_t, scene::Mesh>& meshes, scene::Object& o) {
    for (auto& [material, mesh] : meshes)
      if (!mesh.indices.empty()) o.parts.push_back({scene.addMesh(std::move(mesh)), material});
  }

  // No streets: one scene object per root city object, as the CityJSON importer makes.
  void perObject(std::vector<Built>& built) {
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
  void byBlock(std::vector<Built>& built) {
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

  const std::string& source_;
  const std::string& base_dir_;
  const CityGmlImportOptions& options_;
  CityGmlScene& result_;
  CityGmlStats& st_;
  scene::TextureFiles texture_files_;
  CityMaterials* materials_ = nullptr;
  std::vector<Unit> units_;
  DVec3 origin_{0.0};
  DVec3 used_min_{std::numeric_limits<double>::max()}, used_max_{std::numeric_limits<double>::lowest()};
};

// Parses with libcitygml (from a file or a stream); every way it reports failure becomes an Error naming `source`.
template <class Load>
std::shared_ptr<const citygml::CityModel> parse(const std::string& source, Load&& load) {
  auto logger = std::make_shared<Logger>();
  std::shared_ptr<const citygml::CityModel> model;
  try {
    model = load(logger);
  } catch (const xercesc::SAXParseException& e) {
    throw Error(source, "line " + std::to_string(e.getLineNumber()) + ", column " + std::to_string(e.getColumnNumber()) +
                            ": not well-formed XML (truncated or corrupt file?): " + narrow(e.getMessage()));
  } catch (const xercesc::XMLException& e) {
    throw Error(source, "cannot read XML: " + narrow(e.getMessage()));
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error(source, std::string("cannot read CityGML: ") + e.what());
  } catch (...) {
    throw Error(source, "cannot read CityGML (the parser failed without a message)");
  }
  if (!model)
    throw Error(source, "no CityGML CityModel in the document" +
                            (logger->first_error.empty() ? std::string() : " (" + logger->first_error + ")"));
  return model;
}

citygml::ParserParams parserParams() {
  citygml::ParserParams params;
  params.tesselate = false;  // triangulated here (see the file comment)
  params.optimize = false;
  params.pruneEmptyObjects = false;
  return params;
}

CityGmlScene importModel(const citygml::CityModel& model, const std::string& source, const std::string& base_dir,
                         const std::string& version, double read_s, const CityGmlImportOptions& options) {
  CityGmlScene result;
  result.stats.version = version;
  result.stats.read_s = read_s;
  Importer(source, base_dir, options, result).run(model);
  return result;
}

void checkVersion(const std::string& source, const std::string& version) {
  if (version == "3.0") throw Error(source, "CityGML 3.0 is not supported (supported: 1.0, 2.0)");
}

}  // namespace

size_t CityGmlStats::skippedTotal() const {
  size_t n = 0;
  for (const auto& [reason, count] : skipped) n += count;
  return n;
}

CityGmlScene importCityGml(const std::string& path, const CityGmlImportOptions& options) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw Error(path, "file not found");
  if (!fs::is_regular_file(path, ec)) throw Error(path, "not a regular file");
  std::string head(65536, '\0');
  {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path, "cannot open file");
    in.read(head.data(), std::streamsize(head.size()));
    head.resize(size_t(in.gcount()));
  }
  if (head.empty()) throw Error(path, "empty file");
  const std::string version = versionOf(head);
  checkVersion(path, version);
  Stopwatch clock;
  const auto model = parse(path, [&](std::shared_ptr<Logger> logger) {
    return citygml::load(path, parserParams(), logger);
  });
  return importModel(*model, path, fs::path(path).parent_path().string(), version, clock.seconds(), options);
}

CityGmlScene importCityGmlText(const std::string& text, const std::string& source, const std::string& base_dir,
                               const CityGmlImportOptions& options) {
  if (text.empty()) throw Error(source, "empty document");
  const std::string version = versionOf(text.substr(0, 65536));
  checkVersion(source, version);
  Stopwatch clock;
  const auto model = parse(source, [&](std::shared_ptr<Logger> logger) {
    std::istringstream in(text);
    return citygml::load(in, parserParams(), logger);
  });
  return importModel(*model, source, base_dir, version, clock.seconds(), options);
}

}  // namespace farfield::geodata
