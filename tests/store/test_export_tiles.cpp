// The 3D Tiles export: the tileset checks refuse hand-broken tilesets, the ENU transform against the ellipsoid, the
// georeference through PROJ against the meridian convergence, the deviation measure on a constructed case, and a
// small generated city exported with GL (llvmpipe) whose structure, content and geometric errors are checked against
// the city's own triangles by brute force.
#include "farfield/store/export_tiles.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>

#include <nlohmann/json.hpp>

#include "farfield/core/error.h"
#include "farfield/gen/city.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/renderer.h"
#include "farfield/scene/builtin.h"
#include "farfield/scene/export_gltf.h"
#include "farfield/scene/import.h"
#include "farfield/store/export_georef.h"
#include "farfield/store/export_tiles_check.h"
#include "farfield/store/export_tiles_deviation.h"
#include "support/test_support.h"

namespace farfield::store {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

bool anyContains(const std::vector<std::string>& problems, const std::string& text) {
  return std::any_of(problems.begin(), problems.end(), [&](const std::string& p) { return p.find(text) != std::string::npos; });
}

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& p : v) s += p + "\n";
  return s;
}

// A two-level tileset over one cube (builtin "cube": 2 m, centred at z = 1) written the right way: content turned to
// glTF's Y up, boxes in the Z-up frame.
struct HandTileset {
  fs::path dir;
  json tileset;

  explicit HandTileset(const std::string& name) : dir(test::scratchDir(name)) {
    scene::exportGlb(scene::builtinScene("cube"), (dir / "cube.glb").string());
    const Box3 b = scene::builtinScene("cube").bounds();
    const Vec3 c = b.center(), h = b.extent() * 0.5f;
    tileset = {{"asset", {{"version", "1.1"}}},
               {"geometricError", 100.0},
               {"root",
                {{"boundingVolume", {{"box", {c.x, c.y, c.z, 2 * h.x, 0, 0, 0, 2 * h.y, 0, 0, 0, 2 * h.z}}}},
                 {"geometricError", 10.0},
                 {"refine", "REPLACE"},
                 {"children",
                  {{{"boundingVolume", {{"box", {c.x, c.y, c.z, h.x, 0, 0, 0, h.y, 0, 0, 0, h.z}}}},
                    {"geometricError", 0.0},
                    {"content", {{"uri", "cube.glb"}}}}}}}}};
  }
  std::vector<std::string> check() const {
    std::ofstream(dir / "tileset.json") << tileset.dump(1);
    return checkTileset((dir / "tileset.json").string());
  }
  json& child() { return tileset["root"]["children"][0]; }
};

TEST(TilesetCheck, AcceptsAWellFormedTileset) {
  HandTileset t("tiles_check_ok");
  EXPECT_TRUE(t.check().empty()) << joined(t.check());
  // A sphere around the child box and an ENU-like transform on the root are fine too.
  t.tileset["root"]["transform"] = {0, 1, 0, 0, -1, 0, 0, 0, 0, 0, 1, 0, 1000, 2000, 3000, 1};
  t.tileset["root"]["boundingVolume"] = {{"sphere", {0, 0, 1, 5}}};
  EXPECT_TRUE(t.check().empty()) << joined(t.check());
}

TEST(TilesetCheck, RefusesAChildOutsideItsParent) {
  HandTileset t("tiles_check_outside");
  t.child()["boundingVolume"]["box"][0] = 3.0;  // centre moved 3 m along x: sticks out of the 4 m root box
  const auto p = t.check();
  EXPECT_TRUE(anyContains(p, "root.children[0].boundingVolume: lies outside its parent's by")) << joined(p);
  // Its content moved with the box? No: the cube stayed, so it is outside the child's volume as well.
  EXPECT_TRUE(anyContains(p, "content lies outside the tile's bounding volume")) << joined(p);
}

TEST(TilesetCheck, RefusesAnIncreasingGeometricError) {
  HandTileset t("tiles_check_error");
  t.child()["geometricError"] = 10.5;
  const auto p = t.check();
  EXPECT_TRUE(anyContains(p, "root.children[0].geometricError: 10.5 exceeds its parent's 10")) << joined(p);
  t.child()["geometricError"] = 0.0;
  t.tileset["geometricError"] = 5.0;  // below the root's
  EXPECT_TRUE(anyContains(t.check(), "is below the root tile's")) << joined(t.check());
}

TEST(TilesetCheck, RefusesAMissingFile) {
  HandTileset t("tiles_check_missing");
  t.child()["content"]["uri"] = "tiles/nothing.glb";
  EXPECT_TRUE(anyContains(t.check(), "'tiles/nothing.glb' does not resolve")) << joined(t.check());
  EXPECT_TRUE(anyContains(checkTileset((t.dir / "none.json").string()), "cannot be read"));
}

TEST(TilesetCheck, RefusesMissingAssetRootAndRefine) {
  HandTileset t("tiles_check_asset");
  t.tileset["asset"].erase("version");
  t.tileset["root"].erase("refine");
  auto p = t.check();
  EXPECT_TRUE(anyContains(p, "asset.version")) << joined(p);
  EXPECT_TRUE(anyContains(p, "root.refine: missing")) << joined(p);
  t.tileset["asset"]["version"] = "1.1";
  t.tileset["root"]["refine"] = "MERGE";
  EXPECT_TRUE(anyContains(t.check(), "root.refine: must be")) << joined(t.check());
  t.tileset.erase("root");
  EXPECT_TRUE(anyContains(t.check(), "root: missing")) << joined(t.check());
  EXPECT_THROW(requireValidTileset((t.dir / "tileset.json").string()), Error);
}

TEST(TilesetCheck, RefusesContentLeftZUp) {
  // The content written without the Z-up to Y-up turn stands on its side after 3D Tiles' y-up to z-up turn.
  HandTileset t("tiles_check_zup");
  scene::Scene tall;
  tall.addMesh(scene::builtinScene("cube").meshes[0]);
  scene::GltfBuilder builder((t.dir / "cube.glb").string());
  scene::Material m;
  scene::Mesh mesh = scene::builtinScene("cube").meshes[0];
  for (Vec3& p : mesh.positions) p.z += 1.0f;  // the cube from z 0 to 2, not turned
  mesh.computeBounds();
  builder.addNode("cube", builder.addMesh(mesh, m, {}, "cube"), -1, Mat4(1.0f), nullptr);
  builder.write();
  EXPECT_TRUE(anyContains(t.check(), "content lies outside the tile's bounding volume")) << joined(t.check());
}

TEST(EnuTransform, MatchesTheEllipsoid) {
  // lon 0, lat 0: east is +y, north +z, up +x, the origin on the equator at the semi-major axis.
  const DMat4 m0 = enuTransform({0.0, 0.0, 0.0, 0.0});
  EXPECT_NEAR(glm::distance(DVec3(m0[3]), DVec3(6378137.0, 0, 0)), 0.0, 1e-6);
  EXPECT_NEAR(glm::distance(DVec3(m0[0]), DVec3(0, 1, 0)), 0.0, 1e-12);
  EXPECT_NEAR(glm::distance(DVec3(m0[1]), DVec3(0, 0, 1)), 0.0, 1e-12);
  for (const GeoOrigin o : {GeoOrigin{8.54, 47.37, 400.0, 0.0}, GeoOrigin{-122.4, 37.8, 10.0, 0.02},
                            GeoOrigin{151.2, -33.9, 50.0, -0.03}}) {
    const DMat4 m = enuTransform(o);
    // On the ellipsoid (b = a (1 - f)) at height 0; 100 m up along the up column at height 100.
    const DVec3 p = geodeticToEcef(o.lon_deg, o.lat_deg, 0.0);
    const double a = 6378137.0, b = a * (1.0 - 1.0 / 298.257223563);
    EXPECT_NEAR(p.x * p.x / (a * a) + p.y * p.y / (a * a) + p.z * p.z / (b * b), 1.0, 1e-12);
    const DVec3 up = geodeticToEcef(o.lon_deg, o.lat_deg, o.height_m + 100.0) - DVec3(m[3]);
    EXPECT_NEAR(glm::distance(up / 100.0, DVec3(m[2])), 0.0, 1e-9);
    // Orthonormal, right-handed.
    EXPECT_NEAR(glm::dot(DVec3(m[0]), DVec3(m[1])), 0.0, 1e-12);
    EXPECT_NEAR(glm::distance(glm::cross(DVec3(m[0]), DVec3(m[1])), DVec3(m[2])), 0.0, 1e-12);
    // The scene's +y, turned back by the grid rotation, points to growing latitude (finite difference).
    const DVec3 north =
        glm::normalize(geodeticToEcef(o.lon_deg, o.lat_deg + 1e-6, o.height_m) - DVec3(m[3]));
    const double c = std::cos(o.grid_rotation_rad), s = std::sin(o.grid_rotation_rad);
    EXPECT_NEAR(glm::distance(c * DVec3(m[1]) + s * DVec3(m[0]), north), 0.0, 1e-6);
  }
}

// A capture of the plane z = 0 from 100 m above (as the exporter's), by projecting it: no GL.
impostor::ImpostorCapture planeCapture(int size) {
  impostor::ImpostorCapture cap;
  Camera& cam = cap.camera;
  cam.eye = Vec3(0, 0, 100);
  cam.at = Vec3(0, 0, 0);
  cam.up = Vec3(0, 1, 0);
  cam.fov_y = float(degToRad(10.0));
  cam.width = cam.height = size;
  cam.near_plane = 50.0f;
  cam.far_plane = 120.0f;
  cap.color = image::ColorImage(size, size, image::Rgba8(200, 200, 200, 255));
  cap.depth = image::DepthImage(size, size, 0.0f);
  cap.ids = image::IdImage(size, size, 1u);
  // Window depth of z = 0 seen along the axis: the plane is perpendicular to the view, so every pixel has the depth
  // of the centre's point at linear distance 100 m.
  const float depth = cam.project(Vec3(0, 0, 0)).z;
  for (float& d : cap.depth.pixels()) d = depth;
  cap.data_pixels = size_t(size) * size_t(size);
  return cap;
}

TEST(TilesDeviation, MeasuresAnOffsetPlane) {
  const impostor::ImpostorCapture cap = planeCapture(64);
  // The plane seen covers |x|, |y| <= 100 tan(5 deg) = 8.75 m; a mesh over it lifted by 0.5 m.
  scene::Mesh mesh;
  const float r = 8.8f;
  mesh.positions = {{-r, -r, 0.5f}, {r, -r, 0.5f}, {r, r, 0.5f}, {-r, r, 0.5f}};
  mesh.indices = {0, 1, 2, 0, 2, 3};
  const Deviation d = measureDeviation(mesh, cap);
  EXPECT_NEAR(d.surface_to_mesh, 0.5, 1e-3);
  // Each mesh sample is 0.5 m above the plane and at most half a texel diagonal from a pixel centre (the mesh
  // overhangs the last pixel centres by a little more at its border).
  const double s = 2.0 * 100.0 * std::tan(degToRad(5.0)) / 64.0;
  EXPECT_NEAR(d.texel, s, 1e-4);
  EXPECT_GE(d.mesh_to_surface, 0.5);
  EXPECT_LE(d.mesh_to_surface, std::hypot(0.5, 0.05 + s));
  EXPECT_NEAR(d.metres, std::max(d.surface_to_mesh, d.mesh_to_surface) + d.texel / std::sqrt(2.0), 1e-9);
  // A step: a 3 m box on the plane in the capture, absent from the mesh, is 3 m away (its top) from the mesh.
  impostor::ImpostorCapture stepped = cap;
  const float top = cap.camera.project(Vec3(0, 0, 3)).z;
  for (int y = 28; y < 36; ++y)
    for (int x = 28; x < 36; ++x) stepped.depth.at(x, y) = top;
  mesh.positions = {{-r, -r, 0.0f}, {r, -r, 0.0f}, {r, r, 0.0f}, {-r, r, 0.0f}};
  const Deviation step = measureDeviation(mesh, stepped);
  EXPECT_NEAR(step.surface_to_mesh, 3.0, 0.01);
  EXPECT_THROW(measureDeviation(scene::Mesh{}, cap), Error);
}

// Brute-force distance from p to the nearest of the triangles.
double bruteDistance(const Vec3& p, const std::vector<std::array<Vec3, 3>>& tris) {
  double best = 1e30;
  for (const auto& t : tris) {
    // Project onto the plane, clamp through the three edges: the closest point by sampling edges and the interior.
    const Vec3 n = glm::cross(t[1] - t[0], t[2] - t[0]);
    const float area2 = glm::length(n);
    if (area2 > 1e-12f) {
      const Vec3 u = n / area2;
      const Vec3 q = p - u * glm::dot(p - t[0], u);
      const float w0 = glm::dot(glm::cross(t[2] - t[1], q - t[1]), u), w1 = glm::dot(glm::cross(t[0] - t[2], q - t[2]), u),
                  w2 = glm::dot(glm::cross(t[1] - t[0], q - t[0]), u);
      if (w0 >= 0 && w1 >= 0 && w2 >= 0) best = std::min(best, double(glm::distance(p, q)));
    }
    for (int e = 0; e < 3; ++e) {
      const Vec3 a = t[size_t(e)], b = t[size_t((e + 1) % 3)];
      const float len2 = glm::dot(b - a, b - a);
      const float s = len2 > 0 ? std::clamp(glm::dot(p - a, b - a) / len2, 0.0f, 1.0f) : 0.0f;
      best = std::min(best, double(glm::distance(p, a + s * (b - a))));
    }
  }
  return best;
}

std::vector<std::array<Vec3, 3>> worldTriangles(const scene::Scene& s, const std::vector<uint32_t>& ids) {
  std::vector<std::array<Vec3, 3>> out;
  for (uint32_t id : ids) {
    const scene::Object& o = s.object(id);
    for (const scene::Part& p : o.parts) {
      const scene::Mesh& m = s.meshes[p.mesh];
      for (size_t i = 0; i + 2 < m.indices.size(); i += 3) {
        std::array<Vec3, 3> t;
        for (int k = 0; k < 3; ++k) t[size_t(k)] = Vec3(o.transform * Vec4(m.positions[m.indices[i + size_t(k)]], 1.0f));
        out.push_back(t);
      }
    }
  }
  return out;
}

TEST(ExportTilesGl, SmallCityTilesetIsValidAndItsErrorsHold) {
  gen::CityOptions co;
  co.blocks = 10;
  co.detail = 0;
  co.seed = 2;
  const gen::City city = gen::generateCity(co);
  const scene::Scene& scene = city.scene;
  gpu::sharedHeadlessContext();
  const gpu::GpuScene gpu_scene(scene);
  gpu::Renderer renderer;
  size_t captures = 0;
  const CaptureFn capture = [&](const Camera& camera, std::span<const uint32_t> objects) {
    ++captures;
    return impostor::captureView(renderer, gpu_scene, objects, camera);
  };
  TilesOptions options;
  options.bound = {2.0, 640, 480, degToRad(60.0)};
  options.leaf_objects = 3;
  options.texels = 128;
  const fs::path dir = test::scratchDir("export_tiles_city");
  const TilesetStats stats = exportTiles(scene, capture, dir.string(), options);

  const std::vector<std::string> problems = checkTileset((dir / "tileset.json").string());
  EXPECT_TRUE(problems.empty()) << joined(problems);
  EXPECT_GE(stats.inner, 2u);
  EXPECT_EQ(captures, stats.inner);
  EXPECT_EQ(stats.tiles.size(), stats.inner + stats.leaves);
  EXPECT_NEAR(stats.max_sse, options.bound.angle() * options.bound.focalPixels(), 1e-12);
  EXPECT_LT(stats.max_sse, 2.0);  // the corner pixel is smaller than the centre one

  // Every object with triangles is in exactly one leaf: the leaves' contents read back hold each object once.
  std::multiset<std::string> names;
  for (const TileStats& t : stats.tiles) {
    ASSERT_TRUE(fs::exists(dir / t.content)) << t.content;
    if (!t.leaf) continue;
    const scene::Scene back = scene::importScene((dir / t.content).string());
    EXPECT_EQ(back.objects.size(), t.objects.size());
    for (const scene::Object& o : back.objects) names.insert(o.name);
  }
  size_t with_triangles = 0;
  for (const scene::Object& o : scene.objects)
    if (o.parts.size() && scene.meshes[o.parts[0].mesh].triangleCount()) {
      ++with_triangles;
      EXPECT_EQ(names.count(o.name), 1u) << o.name;
    }
  EXPECT_EQ(names.size(), with_triangles);

  // Inner tiles: the error covers the bound's texel term, and the mesh read back lies within its error of the
  // city's triangles (mesh vertices -> geometry), and the city's roofs (faces turned up, seen from above) within it
  // of the mesh: brute force over every triangle, independent of measureDeviation's grids.
  const std::vector<uint32_t> all_ids = [&] {
    std::vector<uint32_t> v;
    for (const scene::Object& o : scene.objects) v.push_back(o.id);
    return v;
  }();
  const auto city_tris = worldTriangles(scene, all_ids);
  size_t checked = 0;
  for (const TileStats& t : stats.tiles) {
    if (t.leaf) {
      EXPECT_EQ(t.geometric_error, 0.0);
      continue;
    }
    EXPECT_GE(t.geometric_error, options.bound.pixels * t.texel_m);
    EXPECT_GE(t.geometric_error, t.deviation_m);
    EXPECT_GT(t.deviation_m, 0.0);
    const scene::Scene back = scene::importScene((dir / t.content).string());
    ASSERT_EQ(back.objects.size(), 1u) << t.id;
    const auto mesh_tris = worldTriangles(back, {1});
    ASSERT_FALSE(mesh_tris.empty());
    double worst_mesh = 0.0;
    for (size_t i = 0; i < mesh_tris.size(); i += 7)
      for (const Vec3& v : mesh_tris[i]) worst_mesh = std::max(worst_mesh, bruteDistance(v, city_tris));
    EXPECT_LE(worst_mesh, t.deviation_m) << t.id;
    // Roof samples: centroids of the upward faces of the tile's objects, inside its mesh's footprint.
    Box3 footprint;
    for (const auto& tri : mesh_tris)
      for (const Vec3& v : tri) footprint.expand(v);
    double worst_roof = 0.0;
    size_t roofs = 0;
    for (const auto& tri : worldTriangles(scene, t.objects)) {
      const Vec3 n = glm::cross(tri[1] - tri[0], tri[2] - tri[0]);
      if (glm::length(n) < 1e-6f || glm::normalize(n).z < 0.99f) continue;
      const Vec3 c = (tri[0] + tri[1] + tri[2]) / 3.0f;
      if (c.x < footprint.lo.x + 2 * float(t.texel_m) || c.x > footprint.hi.x - 2 * float(t.texel_m) ||
          c.y < footprint.lo.y + 2 * float(t.texel_m) || c.y > footprint.hi.y - 2 * float(t.texel_m) || c.z < 0.5f)
        continue;
      worst_roof = std::max(worst_roof, bruteDistance(c, mesh_tris));
      ++roofs;
    }
    EXPECT_LE(worst_roof, t.deviation_m) << t.id << " over " << roofs << " roof samples";
    ++checked;
  }
  EXPECT_GE(checked, 2u);
}

TEST(ExportTiles, RefusesBadInput) {
  const CaptureFn none = [](const Camera&, std::span<const uint32_t>) -> impostor::ImpostorCapture {
    throw Error("capture", "not expected");
  };
  TilesOptions options;
  EXPECT_THROW(exportTiles(scene::Scene{}, none, test::scratchDir("tiles_empty").string(), options), Error);
  options.leaf_objects = 0;
  EXPECT_THROW(exportTiles(scene::builtinScene("cube"), none, test::scratchDir("tiles_bad").string(), options), Error);
  // A folder that cannot be made: a file stands where it would go.
  options.leaf_objects = 8;
  const fs::path blocker = test::scratchDir("tiles_blocked") / "file";
  std::ofstream(blocker) << "x";
  try {
    exportTiles(scene::builtinScene("cube"), none, (blocker / "tiles").string(), options);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot be written"), std::string::npos) << e.what();
  }
  // One object: a single leaf root, no capture.
  const TilesetStats one = exportTiles(scene::builtinScene("cube"), none, test::scratchDir("tiles_one").string(), options);
  EXPECT_EQ(one.tiles.size(), 1u);
  EXPECT_EQ(one.leaves, 1u);
}

TEST(GeoOrigin, UtmOriginsAndTheirGridConvergence) {
  const fs::path dir = test::scratchDir("tiles_georef");
  auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream((dir / name).string()) << text;
    return (dir / name).string();
  };
  EXPECT_FALSE(readGeoOrigin((dir / "none.georef.json").string()));
  // UTM zone 32N: easting 500 km is the central meridian (9 E); northing 0 the equator.
  const auto o = readGeoOrigin(write(
      "a.json", R"({"format": "farfield-georef", "version": 1, "crs": "EPSG:32632", "origin": [500000, 0, 0]})"));
  ASSERT_TRUE(o);
  EXPECT_NEAR(o->lon_deg, 9.0, 1e-9);
  EXPECT_NEAR(o->lat_deg, 0.0, 1e-9);
  EXPECT_NEAR(o->grid_rotation_rad, 0.0, 1e-9);
  // 100 km east of it at 45 N: grid north lies east of true north by about (lon - 9 deg) sin(lat) (the first term
  // of the meridian convergence), so the scene's +y is turned clockwise: a negative rotation.
  const auto e = readGeoOrigin(write(
      "b.json", R"({"format": "farfield-georef", "version": 1, "crs": "EPSG:32632", "origin": [600000, 5000000, 30]})"));
  ASSERT_TRUE(e);
  EXPECT_GT(e->lon_deg, 10.2);
  EXPECT_LT(e->lon_deg, 10.35);
  EXPECT_NEAR(e->lat_deg, 45.1, 0.1);
  const double expected = -degToRad(e->lon_deg - 9.0) * std::sin(degToRad(e->lat_deg));
  EXPECT_NEAR(e->grid_rotation_rad, expected, 0.02 * std::abs(expected));
  EXPECT_NEAR(e->height_m, 30.0, 1e-6);
  // Bad files name themselves.
  for (const std::string& bad : {std::string("{"), std::string(R"({"format": "other"})"),
                                 std::string(R"({"format": "farfield-georef", "crs": "EPSG:32632"})"),
                                 std::string(R"({"format": "farfield-georef", "crs": "NOT:A:CRS", "origin": [0, 0, 0]})")}) {
    const std::string path = write("bad.json", bad);
    try {
      readGeoOrigin(path);
      ADD_FAILURE() << bad;
    } catch (const Error& err) {
      EXPECT_NE(std::string(err.what()).find("bad.json"), std::string::npos) << err.what();
    }
  }
}

}  // namespace
}  // namespace farfield::store
