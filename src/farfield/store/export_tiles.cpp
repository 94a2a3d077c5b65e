// The 3D Tiles export (see the header): the quadtree, each tile's content and geometric error, tileset.json.
// Tiles are built bottom-up (an inner tile's error needs its children's), written as they are built, and the
// tileset is checked (export_tiles_check.h) before the export reports success.
#include "farfield/store/export_tiles.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "farfield/core/error.h"
#include "farfield/core/progress.h"
#include "farfield/impostor/contour.h"
#include "farfield/impostor/impostor_mesh.h"
#include "farfield/scene/export_gltf.h"
#include "farfield/store/export_tiles_check.h"
#include "farfield/store/export_tiles_deviation.h"
#include "farfield/store/export_tiles_heightfield.h"

namespace farfield::store {

DVec3 geodeticToEcef(double lon_deg, double lat_deg, double height_m) {
  constexpr double a = 6378137.0, f = 1.0 / 298.257223563;
  constexpr double e2 = f * (2.0 - f);
  const double lon = degToRad(lon_deg), lat = degToRad(lat_deg);
  const double n = a / std::sqrt(1.0 - e2 * std::sin(lat) * std::sin(lat));
  return {(n + height_m) * std::cos(lat) * std::cos(lon), (n + height_m) * std::cos(lat) * std::sin(lon),
          (n * (1.0 - e2) + height_m) * std::sin(lat)};
}

DMat4 enuTransform(const GeoOrigin& o) {
  const double lon = degToRad(o.lon_deg), lat = degToRad(o.lat_deg);
  const DVec3 east(-std::sin(lon), std::cos(lon), 0.0);
  const DVec3 north(-std::sin(lat) * std::cos(lon), -std::sin(lat) * std::sin(lon), std::cos(lat));
  const DVec3 up(std::cos(lat) * std::cos(lon), std::cos(lat) * std::sin(lon), std::sin(lat));
  // The scene's +y is true north turned by grid_rotation_rad counter-clockwise; +x is +y turned clockwise by 90 deg.
  const double c = std::cos(o.grid_rotation_rad), s = std::sin(o.grid_rotation_rad);
  const DVec3 y_axis = c * north - s * east;
  const DVec3 x_axis = c * east + s * north;
  DMat4 m(1.0);
  m[0] = glm::dvec4(x_axis, 0.0);
  m[1] = glm::dvec4(y_axis, 0.0);
  m[2] = glm::dvec4(up, 0.0);
  m[3] = glm::dvec4(geodeticToEcef(o.lon_deg, o.lat_deg, o.height_m), 1.0);
  return m;
}

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr float kCaptureFovDeg = 10.0f;  // the widest top-down capture

struct Node {
  Box2 square;
  int level = 0, x = 0, y = 0;
  std::vector<uint32_t> objects;
  std::vector<Node> children;
};

Vec2 groundPosition(const scene::Scene& scene, uint32_t id) { return Vec2(scene.object(id).world_bounds.center()); }

Node buildQuadtree(const scene::Scene& scene, Box2 square, int level, int x, int y, std::vector<uint32_t> objects,
                   const TilesOptions& options) {
  Node node;
  node.square = square;
  node.level = level;
  node.x = x;
  node.y = y;
  if (objects.size() <= options.leaf_objects || level >= options.max_depth) {
    node.objects = std::move(objects);
    return node;
  }
  const Vec2 mid = square.center();
  std::vector<uint32_t> quadrant[4];
  for (uint32_t id : objects) {
    const Vec2 p = groundPosition(scene, id);
    quadrant[(p.x >= mid.x ? 1 : 0) + (p.y >= mid.y ? 2 : 0)].push_back(id);
  }
  auto sub = [&](int q) {
    Box2 b;
    b.lo = Vec2((q & 1) ? mid.x : square.lo.x, (q & 2) ? mid.y : square.lo.y);
    b.hi = Vec2((q & 1) ? square.hi.x : mid.x, (q & 2) ? square.hi.y : mid.y);
    return b;
  };
  int non_empty = 0, last = 0;
  for (int q = 0; q < 4; ++q)
    if (!quadrant[q].empty()) ++non_empty, last = q;
  // One non-empty quadrant: that quadrant is this node (no inner tile that would equal its only child).
  if (non_empty == 1)
    return buildQuadtree(scene, sub(last), level + 1, 2 * x + (last & 1), 2 * y + (last >> 1) , std::move(quadrant[last]),
                         options);
  for (int q = 0; q < 4; ++q)
    if (!quadrant[q].empty())
      node.children.push_back(buildQuadtree(scene, sub(q), level + 1, 2 * x + (q & 1), 2 * y + (q >> 1),
                                            std::move(quadrant[q]), options));
  for (const Node& c : node.children) node.objects.insert(node.objects.end(), c.objects.begin(), c.objects.end());
  return node;
}

size_t countInner(const Node& n) {
  size_t c = n.children.empty() ? 0 : 1;
  for (const Node& k : n.children) c += countInner(k);
  return c;
}

json boxJson(const Box3& b) {
  const Vec3 c = b.center();
  // Half extents of at least 5 mm: a flat box (a ground plane) keeps three independent axes.
  const Vec3 h = glm::max(b.extent() * 0.5f, Vec3(0.005f));
  return json{c.x, c.y, c.z, h.x, 0.0, 0.0, 0.0, h.y, 0.0, 0.0, 0.0, h.z};
}

json matrixJson(const DMat4& m) {
  json a = json::array();
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) a.push_back(m[c][r]);
  return a;
}

class TilesWriter {
 public:
  TilesWriter(const scene::Scene& scene, const CaptureFn& capture, const std::string& dir, const TilesOptions& options,
              TilesetStats& stats, size_t inner_total)
      : scene_(scene),
        capture_(capture),
        dir_(dir),
        options_(options),
        stats_(stats),
        progress_("export tiles", inner_total) {}

  // The tile of `node` (children first); its bounds and error come back through the json.
  json write(const Node& node, Box3& bounds) {
    const size_t slot = stats_.tiles.size();
    stats_.tiles.emplace_back();
    TileStats tile;
    tile.id = std::to_string(node.level) + "_" + std::to_string(node.x) + "_" + std::to_string(node.y);
    tile.level = node.level;
    tile.leaf = node.children.empty();
    tile.objects = node.objects;
    stats_.depth = std::max(stats_.depth, node.level);
    json j = json::object();
    bounds = Box3();
    double children_error = 0.0;
    if (!tile.leaf) {
      json children = json::array();
      for (const Node& c : node.children) {
        Box3 cb;
        children.push_back(write(c, cb));
        bounds.expand(cb);
        children_error = std::max(children_error, children.back()["geometricError"].get<double>());
      }
      j["children"] = std::move(children);
    }
    tile.content = "tiles/" + tile.id + ".glb";
    const std::string path = (fs::path(dir_) / tile.content).string();
    scene::GltfBuilder builder(path);
    if (tile.leaf) {
      builder.addObjects(scene_, node.objects);
      for (uint32_t id : node.objects) {
        bounds.expand(scene_.object(id).world_bounds);
        for (const scene::Part& p : scene_.object(id).parts) tile.triangles += scene_.meshes[p.mesh].triangleCount();
      }
      ++stats_.leaves;
    } else {
      writeInner(node, builder, tile, bounds);
      tile.geometric_error = std::max({tile.deviation_m, options_.bound.pixels * tile.texel_m, children_error});
      ++stats_.inner;
      progress_.advance();
    }
    tile.bytes = builder.write();
    stats_.bytes += tile.bytes;
    j["boundingVolume"] = {{"box", boxJson(bounds)}};
    j["geometricError"] = tile.geometric_error;
    j["content"] = {{"uri", tile.content}};
    stats_.tiles[slot] = tile;
    return j;
  }

 private:
  // A textured heightfield mesh of the node's objects seen from straight above (export_tiles_heightfield.h).
  void writeInner(const Node& node, scene::GltfBuilder& builder, TileStats& tile, Box3& bounds) {
    Box3 objects;
    for (uint32_t id : node.objects) objects.expand(scene_.object(id).world_bounds);
    const int texels = stats_.texels;
    const Vec3 extent = objects.extent();
    // Two texels of margin around the objects' square.
    const float half_side = 0.5f * std::max({extent.x, extent.y, 1e-3f}) * (1.0f + 4.0f / float(texels));
    // Near-orthographic: from so far that the top of the tallest object and the ground below it are seen at most
    // half a texel apart across the image (perspective would show the ground beside a tall wall shifted by its
    // height times the pixel offset over the distance, and the mesh would slant there); at most 10 degrees.
    const float height = std::max(extent.z, 1.0f);
    const float half_fov =
        std::atan(std::min(std::tan(float(degToRad(kCaptureFovDeg)) * 0.5f), 0.5f * half_side / (height * float(texels))));
    const float distance = half_side / std::tan(half_fov);  // the roofs' plane fills the image
    Camera cam;
    const Vec3 c = objects.center();
    cam.eye = Vec3(c.x, c.y, objects.hi.z + distance);
    cam.at = Vec3(c.x, c.y, objects.lo.z);
    cam.up = Vec3(0, 1, 0);
    cam.fov_y = 2.0f * half_fov;
    cam.width = cam.height = texels;
    cam.near_plane = 0.5f * distance;
    cam.far_plane = distance + extent.z + 1.0f;
    const impostor::ImpostorCapture shot = capture_(cam, node.objects);
    tile.texel_m = 2.0 * double(distance + extent.z) * std::tan(double(half_fov)) / double(texels);
    impostor::DepthMeshImpostor imp;
    const scene::Mesh full = heightfieldMesh(shot);
    if (full.indices.empty()) return;  // nothing seen: an inner tile without content
    // meshoptimizer's error is an estimate: simplify under N s / 2, and again under tighter bounds while the measured
    // deviation exceeds the bound's texel term N s and tightening still lowers it by a tenth (a deviation the full
    // heightfield has too, a spire thinner than a texel, is not worth the triangles).
    const double target = options_.bound.pixels * tile.texel_m;
    Deviation dev;
    for (const double factor : {0.5, 0.1, 0.02}) {
      scene::Mesh mesh = full;
      simplifyMesh(mesh, factor * target);
      const Deviation d = measureDeviation(mesh, shot);
      if (!imp.mesh.indices.empty() && d.metres > 0.9 * dev.metres) break;  // keep the simpler one
      imp.mesh = std::move(mesh);
      dev = d;
      if (dev.metres <= target) break;
    }
    // Alpha 0 off the data (sky, seen from below), as every impostor texture.
    imp.texture = impostor::impostorTexture(shot.color, impostor::dataMask(shot.color, shot.depth));
    tile.deviation_m = dev.metres;
    tile.texel_m = std::max(tile.texel_m, dev.texel);
    tile.triangles = imp.mesh.triangleCount();
    scene::Material m;
    m.name = "tile " + tile.id;
    m.texture = imp.texture;
    m.texture_path = m.name;
    m.unlit = true;
    m.double_sided = true;
    const int mesh = builder.addMesh(imp.mesh, m, {true, 0.5f, true}, m.name);
    builder.addNode(m.name, mesh, -1, scene::worldToGltf(),
                    json{{"farfield_tile",
                          {{"kind", "textured heightfield mesh captured from above, simplified"},
                           {"objects", node.objects.size()},
                           {"deviation_m", dev.metres},
                           {"texel_m", tile.texel_m},
                           {"creation_camera",
                            {{"eye", {cam.eye.x, cam.eye.y, cam.eye.z}}, {"fov_y_deg", radToDeg(double(cam.fov_y))},
                             {"texels", texels}}}}}});
    bounds.expand(imp.mesh.bounds);
  }

  const scene::Scene& scene_;
  const CaptureFn& capture_;
  const std::string& dir_;
  const TilesOptions& options_;
  TilesetStats& stats_;
  Progress progress_;
};

}  // namespace

TilesetStats exportTiles(const scene::Scene& scene, const CaptureFn& capture, const std::string& dir,
                         const TilesOptions& options) {
  options.bound.validate("tiles error bound (--error-px, --size, --fov)");
  if (options.bound.pixels <= 0.0) throw Error("--error-px", "must be above 0");
  if (options.leaf_objects < 1) throw Error("tiles", "leaf objects must be at least 1");
  if (options.max_depth < 1 || options.max_depth > 20) throw Error("tiles", "max depth must be in 1..20");
  if (options.texels != 0 && (options.texels < 64 || options.texels > 4096))
    throw Error("tiles", "texels must be 0 (from the bound) or in 64..4096");

  std::vector<uint32_t> ids;
  Box2 square;
  for (const scene::Object& o : scene.objects) {
    size_t triangles = 0;
    for (const scene::Part& p : o.parts)
      if (p.mesh < scene.meshes.size()) triangles += scene.meshes[p.mesh].triangleCount();
    if (triangles == 0 || o.world_bounds.empty()) continue;
    ids.push_back(o.id);
    square.expand(groundPosition(scene, o.id));
  }
  if (ids.empty()) throw Error(options.scene_name.empty() ? "scene" : options.scene_name, "has no triangles to export");
  // A square root cell (quadrants stay square), slightly larger so that no centre lies on its far edges.
  const Vec2 c = square.center();
  const float half = 0.5f * std::max({square.extent().x, square.extent().y, 1.0f}) * 1.001f;
  square.lo = c - Vec2(half);
  square.hi = c + Vec2(half);
  const Node root = buildQuadtree(scene, square, 0, 0, 0, ids, options);

  try {
    fs::create_directories(fs::path(dir) / "tiles");
    for (const auto& e : fs::directory_iterator(fs::path(dir) / "tiles"))
      if (e.path().extension() == ".glb") fs::remove(e.path());
  } catch (const fs::filesystem_error& e) {
    throw Error(dir, std::string("cannot be written: ") + e.code().message());
  }

  TilesetStats stats;
  stats.texels = options.texels > 0 ? options.texels : std::clamp(options.bound.height, 64, 2048);
  Box3 bounds;
  json root_tile;
  {
    TilesWriter writer(scene, capture, dir, options, stats, countInner(root));
    root_tile = writer.write(root, bounds);
  }
  root_tile["refine"] = "REPLACE";
  if (options.georeference) root_tile["transform"] = matrixJson(enuTransform(*options.georeference));
  stats.root_error = root_tile["geometricError"].get<double>();
  stats.tileset_error = std::max(stats.root_error, double(glm::length(bounds.extent())));
  // CesiumJS's screen-space error is g * f / d with f the centre pixel's focal length; the bound holds at the
  // frame's smallest (corner) pixel: maximumScreenSpaceError = bound.angle() * f.
  stats.max_sse = options.bound.angle() * options.bound.focalPixels();

  json tileset = {
      {"asset",
       {{"version", "1.1"},
        {"generator", "Farfield"},
        {"extras",
         {{"farfield",
           {{"scene", options.scene_name},
            {"error_bound", {{"pixels", options.bound.pixels}, {"width", options.bound.width},
                             {"height", options.bound.height}, {"fov_y_deg", radToDeg(options.bound.fov_y)}}},
            {"maximumScreenSpaceError", stats.max_sse},
            {"texels", stats.texels},
            {"inner_tiles", "textured heightfield mesh captured from above, simplified"},
            {"geometric_error", "leaf 0; inner max(measured deviation, pixels * texel size, children's)"},
            {"frame", options.georeference ? "east-north-up at the georeference's origin" : "local, metres, Z up"}}}}}}},
      {"geometricError", stats.tileset_error},
      {"root", root_tile}};
  const std::string path = (fs::path(dir) / "tileset.json").string();
  const std::string text = tileset.dump(1) + "\n";
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    if (!out) throw Error(path, "cannot open for writing");
    out << text;
    out.close();
    if (!out) throw Error(path, "write failed");
  }
  stats.bytes += text.size();
  requireValidTileset(path);
  return stats;
}

}  // namespace farfield::store
