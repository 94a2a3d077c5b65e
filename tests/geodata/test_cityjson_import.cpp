// CityJSON import: a hand-made file with known areas, volumes, semantics and offsets (2.0 and 1.1, LoD choice),
// malformed files, and the Delft file checked against values computed here from its JSON.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>

#include <nlohmann/json.hpp>

#include "farfield/core/error.h"
#include "farfield/geodata/cityjson_import.h"
#include "support/test_support.h"

using farfield::Error;
using farfield::Vec3;
using farfield::geodata::CityJsonImportOptions;
using farfield::geodata::CityJsonScene;
using farfield::geodata::importCityJson;

namespace {

std::string dataFile(const std::string& name) { return (farfield::test::testDataDir() / "geodata" / name).string(); }

const farfield::scene::Object* objectNamed(const CityJsonScene& c, const std::string& name) {
  for (const auto& o : c.scene.objects)
    if (o.name == name) return &o;
  return nullptr;
}

struct PartMeasures {
  double area = 0;
  double volume = 0;  // signed, divergence theorem
};

PartMeasures measure(const farfield::scene::Mesh& m) {
  PartMeasures r;
  for (size_t i = 0; i < m.indices.size(); i += 3) {
    const glm::dvec3 a(m.positions[m.indices[i]]), b(m.positions[m.indices[i + 1]]), c(m.positions[m.indices[i + 2]]);
    r.area += 0.5 * glm::length(glm::cross(b - a, c - a));
    r.volume += glm::dot(a, glm::cross(b, c)) / 6.0;
  }
  return r;
}

// Per material name: summed area and signed volume of an object's parts.
std::map<std::string, PartMeasures> measureObject(const CityJsonScene& c, const farfield::scene::Object& o) {
  std::map<std::string, PartMeasures> out;
  for (const auto& p : o.parts) {
    const PartMeasures m = measure(c.scene.meshes[p.mesh]);
    out[c.scene.materials[p.material].name].area += m.area;
    out[c.scene.materials[p.material].name].volume += m.volume;
  }
  return out;
}

void expectErrorNaming(const std::string& path, const std::string& fragment) {
  try {
    importCityJson(path);
    ADD_FAILURE() << path << ": no error";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find(fragment), std::string::npos) << what;
    std::printf("  %s\n", what.c_str());
  }
}

}  // namespace

TEST(CityJsonImport, CubeHandComputed) {
  for (const char* name : {"cube.city.json", "cube_v11.city.json"}) {
    SCOPED_TRACE(name);
    const CityJsonScene c = importCityJson(dataFile(name));
    const auto& st = c.stats;
    EXPECT_EQ(st.buildings, 1u);
    EXPECT_EQ(st.building_parts, 1u);
    EXPECT_EQ(st.ground_objects, 2u);
    EXPECT_EQ(st.surfaces, 12u + 1u + 1u);
    EXPECT_EQ(st.semantic_surfaces, 6u);
    EXPECT_EQ(st.inferred_surfaces, 6u);
    EXPECT_EQ(st.holes, 1u);
    EXPECT_EQ(st.triangles, 24u + 8u + 1u);  // quads: 2 each; a 4-gon with a 4-gon hole: 8; a triangle
    EXPECT_EQ(st.skippedTotal(), 0u);
    ASSERT_EQ(c.scene.objects.size(), 3u);
    EXPECT_EQ(c.reference.crs, "EPSG:7415");
    // Vertex bounds (85000..85050, 445000..445040) -> origin at their centre, z kept.
    EXPECT_DOUBLE_EQ(c.reference.origin.x, 85025.0);
    EXPECT_DOUBLE_EQ(c.reference.origin.y, 445020.0);
    EXPECT_DOUBLE_EQ(c.reference.origin.z, 0.0);
    EXPECT_NEAR(c.file_min.x, 85000.0, 1e-9);
    EXPECT_NEAR(c.file_max.y, 445040.0, 1e-9);
    EXPECT_NEAR(c.file_max.z, 1.5 + 14.0, 1e-9);
    const auto b = c.scene.bounds();
    EXPECT_NEAR(b.lo.x, -25.0f, 1e-4f);
    EXPECT_NEAR(b.hi.x, 25.0f, 1e-4f);
    EXPECT_NEAR(b.lo.y, -20.0f, 1e-4f);
    EXPECT_NEAR(b.hi.y, 20.0f, 1e-4f);
    EXPECT_NEAR(b.lo.z, 1.5f, 1e-4f);
    EXPECT_NEAR(b.hi.z, 15.5f, 1e-4f);

    // The house: semantic roof/wall/ground of the 10 m cube plus the 4 m part classified by its normals.
    const auto* house = objectNamed(c, "house");
    ASSERT_NE(house, nullptr);
    const auto parts = measureObject(c, *house);
    ASSERT_EQ(parts.count("roof"), 1u);
    ASSERT_EQ(parts.count("wall"), 1u);
    ASSERT_EQ(parts.count("ground surface"), 1u);
    EXPECT_NEAR(parts.at("roof").area, 100.0 + 16.0, 1e-3);
    EXPECT_NEAR(parts.at("wall").area, 400.0 + 64.0, 1e-3);
    EXPECT_NEAR(parts.at("ground surface").area, 100.0 + 16.0, 1e-3);
    // Two closed cubes, outward: volume 1000 + 64.
    double volume = 0;
    for (const auto& [n, m] : parts) volume += m.volume;
    EXPECT_NEAR(volume, 1064.0, 1e-2);
    // Road with its hole, land use triangle.
    const auto road = measureObject(c, *objectNamed(c, "road"));
    EXPECT_NEAR(road.at("road").area, 600.0 - 50.0, 1e-3);
    const auto field = measureObject(c, *objectNamed(c, "field"));
    EXPECT_NEAR(field.at("land use").area, 50.0, 1e-3);
  }
  // LoD choice: at most LoD 1 the house is its flat LoD1 square and the part (LoD 2.2 only) has nothing.
  CityJsonImportOptions lod1;
  lod1.max_lod = 1.0;
  const CityJsonScene c = importCityJson(dataFile("cube_v11.city.json"), lod1);
  EXPECT_EQ(c.stats.triangles, 2u + 8u + 1u);
  EXPECT_EQ(c.stats.building_parts, 0u);
  // A part linked from one side only ("parents" without the building's "children") is still the building's.
  {
    nlohmann::json doc;
    std::ifstream(dataFile("cube.city.json")) >> doc;
    doc["CityObjects"]["house"].erase("children");
    const std::string one_sided = (farfield::test::scratchDir("geodata_cityjson_links") / "one_sided.city.json").string();
    std::ofstream(one_sided) << doc.dump();
    const CityJsonScene linked = importCityJson(one_sided);
    EXPECT_EQ(linked.scene.objects.size(), 3u);
    EXPECT_EQ(linked.stats.building_parts, 1u);
    EXPECT_EQ(linked.stats.triangles, 33u);
  }
  // Without ground objects only the house is left.
  CityJsonImportOptions no_ground;
  no_ground.ground_objects = false;
  EXPECT_EQ(importCityJson(dataFile("cube.city.json"), no_ground).scene.objects.size(), 1u);
}

TEST(CityJsonImport, BadFacesAreSkippedPerReason) {
  const CityJsonScene c = importCityJson(dataFile("bad_index.city.json"));
  for (const auto& [reason, n] : c.stats.skipped) std::printf("  skipped %-55s %zu\n", reason.c_str(), n);
  EXPECT_EQ(c.stats.triangles, 2u);
  EXPECT_EQ(c.stats.buildings, 1u);
  EXPECT_EQ(c.stats.skippedTotal(), 5u);
  EXPECT_EQ(c.stats.skipped.at("faces with vertex indices out of range or not integers"), 3u);
  EXPECT_EQ(c.stats.skipped.at("faces with fewer than 3 vertices"), 1u);
  EXPECT_EQ(c.stats.skipped.at("faces without area"), 1u);
}

TEST(CityJsonImport, BadFilesNameTheFile) {
  expectErrorNaming(dataFile("all_bad.city.json"), "no usable surface");
  expectErrorNaming(dataFile("unknown_version.city.json"), "unsupported CityJSON version '3.7'");
  expectErrorNaming(dataFile("not_cityjson.city.json"), "not a CityJSON document");
  expectErrorNaming(dataFile("truncated.city.json"), "not valid JSON");
  expectErrorNaming(dataFile("missing.city.json"), "cannot open");
  // Structural damage in a copy of the cube: each still an error or a counted skip, never a crash.
  nlohmann::json doc;
  std::ifstream(dataFile("cube.city.json")) >> doc;
  const auto dir = farfield::test::scratchDir("geodata_cityjson");
  auto write = [&](const std::string& name, const nlohmann::json& j) {
    const std::string p = (dir / name).string();
    std::ofstream(p) << j.dump();
    return p;
  };
  {
    auto d = doc;
    d["transform"]["scale"] = {0.01, "x", 0.01};
    expectErrorNaming(write("bad_transform.city.json", d), "scale");
  }
  {
    auto d = doc;
    d["vertices"] = "none";
    expectErrorNaming(write("bad_vertices.city.json", d), "vertices");
  }
  {
    // Wrong shapes everywhere but the road: the road still imports, the rest is counted.
    auto d = doc;
    d["CityObjects"]["house"]["geometry"][0]["boundaries"] = 7;
    d["CityObjects"]["house-part"]["geometry"][0]["boundaries"] = {{{"a"}}};
    d["CityObjects"]["field"]["geometry"] = {{{"type", "MultiSurface"}, {"lod", "1"}, {"boundaries", {1, 2, 3}}}};
    d["vertices"][0] = {1, 2};  // a malformed vertex: faces using it are skipped
    const CityJsonScene c = importCityJson(write("bad_shapes.city.json", d));
    EXPECT_EQ(c.scene.objects.size(), 1u);
    EXPECT_EQ(c.stats.bad_vertices, 1u);
    EXPECT_GT(c.stats.skippedTotal(), 0u);
    for (const auto& [reason, n] : c.stats.skipped) std::printf("  skipped %-55s %zu\n", reason.c_str(), n);
  }
}

TEST(CityJsonImport, Delft) {
  FF_SHARED_FILE_OR_SKIP(json, "city/delft.city.json");
  const std::string path = json.string();
  const CityJsonScene c = importCityJson(path);
  const auto& st = c.stats;

  // Expected values straight from the JSON.
  nlohmann::json doc;
  std::ifstream(path) >> doc;
  size_t buildings = 0, roots_with_geometry = 0;
  for (const auto& [id, o] : doc["CityObjects"].items()) {
    if (o["type"] == "Building") ++buildings;
    if (!o.contains("parents") && o.contains("geometry") && !o["geometry"].empty()) ++roots_with_geometry;
  }
  const auto& scale = doc["transform"]["scale"];
  const auto& translate = doc["transform"]["translate"];
  const auto& vertices = doc["vertices"];
  glm::dvec3 lo(std::numeric_limits<double>::max()), hi(std::numeric_limits<double>::lowest());
  std::function<void(const nlohmann::json&)> walk = [&](const nlohmann::json& j) {
    if (j.is_array()) {
      for (const auto& k : j) walk(k);
    } else if (j.is_number_integer()) {
      const auto& v = vertices[j.get<size_t>()];
      for (int a = 0; a < 3; ++a) {
        const double x = v[a].get<double>() * scale[a].get<double>() + translate[a].get<double>();
        lo[a] = std::min(lo[a], x);
        hi[a] = std::max(hi[a], x);
      }
    }
  };
  for (const auto& [id, o] : doc["CityObjects"].items())
    for (const auto& g : o["geometry"]) walk(g["boundaries"]);

  std::printf("  delft: CityJSON %s, %zu vertices, %zu buildings, %zu objects, %zu surfaces, %llu triangles, "
              "origin (%.0f, %.0f) in %s\n",
              st.version.c_str(), st.vertices, st.buildings, c.scene.objects.size(), st.surfaces,
              (unsigned long long)st.triangles, c.reference.origin.x, c.reference.origin.y, c.reference.crs.c_str());
  for (const auto& [reason, n] : st.skipped) std::printf("  skipped %-55s %zu\n", reason.c_str(), n);
  for (const auto& [type, n] : st.objects_by_type) std::printf("  %-20s %zu\n", type.c_str(), n);

  EXPECT_EQ(buildings, 160u);
  EXPECT_EQ(st.buildings, buildings);
  EXPECT_EQ(st.vertices, vertices.size());
  EXPECT_EQ(st.version, "2.0");
  EXPECT_EQ(c.reference.crs, "EPSG:7415");
  EXPECT_EQ(c.scene.objects.size(), roots_with_geometry);
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(c.file_min[a], lo[a], 1e-6) << a;
    EXPECT_NEAR(c.file_max[a], hi[a], 1e-6) << a;
  }
  // The scene's float bounds plus the origin give the same box (to float precision near the origin).
  const auto b = c.scene.bounds();
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(double(b.lo[a]) + c.reference.origin[a], lo[a], 1e-3) << a;
    EXPECT_NEAR(double(b.hi[a]) + c.reference.origin[a], hi[a], 1e-3) << a;
  }
  // And the file's own extent agrees.
  const auto& extent = doc["metadata"]["geographicalExtent"];
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(lo[a], extent[a].get<double>(), 1e-3);
    EXPECT_NEAR(hi[a], extent[a + 3].get<double>(), 1e-3);
  }
  c.scene.validate("delft");
}

// Appearances: b2 (a gabled house, its south wall textured with facade.png in theme "summer", its roof a
// diffuseColor material) and b4 (a box whose roof names a texture file that does not exist), written by
// tests/data/geodata/make_appearance_files.py, as CityJSON 2.0 (with a transform) and 1.0 (without).
TEST(CityJsonImport, TexturesMaterialsAndThemes) {
  for (const char* name : {"textured.city.json", "textured_v10.city.json"}) {
    SCOPED_TRACE(name);
    const CityJsonScene c = importCityJson(dataFile(name));
    const auto& st = c.stats;
    EXPECT_EQ(st.texture_themes, (std::vector<std::string>{"summer", "winter"}));
    EXPECT_EQ(st.material_themes, (std::vector<std::string>{"summer"}));
    EXPECT_EQ(st.texture_theme, "summer");
    EXPECT_EQ(st.material_theme, "summer");
    ASSERT_EQ(c.scene.objects.size(), 2u);
    // Hand-computed: b2 = ground 48 + long walls 2 x 48 + gables 2 x (36 + 9) + roofs 2 x 8 x sqrt(18), 16
    // triangles; b4 = 2 x 25 + 4 x 15 = 110, 12 triangles.
    EXPECT_EQ(st.triangles, 16u + 12u);
    EXPECT_EQ(st.textured_surfaces, 2u);  // b2's south wall, b4's roof (placeholder)
    EXPECT_EQ(st.material_surfaces, 2u);  // b2's two roof faces
    EXPECT_EQ(st.bad_texture_references, 0u);
    const auto b2 = measureObject(c, *objectNamed(c, "b2"));
    const double roof = 2.0 * 8.0 * std::sqrt(18.0);
    ASSERT_EQ(b2.count("facade.png"), 1u);
    ASSERT_EQ(b2.count("roof tiles"), 1u);
    EXPECT_NEAR(b2.at("facade.png").area, 48.0, 1e-3);
    EXPECT_NEAR(b2.at("roof tiles").area, roof, 1e-3);
    EXPECT_NEAR(b2.at("wall").area, 48.0 + 90.0, 1e-3);
    EXPECT_NEAR(b2.at("ground surface").area, 48.0, 1e-3);
    double volume = 0.0;
    for (const auto& [n, m] : b2) volume += m.volume;
    EXPECT_NEAR(volume, 8.0 * 6.0 * 6.0 + 0.5 * 6.0 * 3.0 * 8.0, 1e-2);  // closed and outward
    const auto b4 = measureObject(c, *objectNamed(c, "b4"));
    ASSERT_EQ(b4.count("textures/missing_roof.jpg"), 1u);
    EXPECT_NEAR(b4.at("textures/missing_roof.jpg").area, 25.0, 1e-3);

    for (const auto& p : objectNamed(c, "b2")->parts) {
      const auto& m = c.scene.materials[p.material];
      const auto& mesh = c.scene.meshes[p.mesh];
      if (m.name == "roof tiles") {
        EXPECT_EQ(m.base_color, farfield::Vec4(0.8f, 0.2f, 0.1f, 1.0f));
        EXPECT_FALSE(m.texture);
      }
      if (m.name != "facade.png") continue;
      // The texture itself: 4 x 2, row 0 red, green, blue, white.
      ASSERT_TRUE(m.texture);
      ASSERT_EQ(m.texture->width(), 4);
      EXPECT_EQ(m.texture->at(0, 0), farfield::image::Rgba8(255, 0, 0, 255));
      EXPECT_EQ(m.texture->at(3, 1), farfield::image::Rgba8(255, 0, 255, 255));
      EXPECT_NE(m.texture_path.find("facade.png"), std::string::npos);
      // The file maps u = (x - west) / 8 and v = height / 6 from the bottom; Farfield's v runs from the top.
      ASSERT_EQ(mesh.uvs.size(), mesh.positions.size());
      float west = 1e9f, base = 1e9f;
      for (const auto& q : mesh.positions) west = std::min(west, q.x), base = std::min(base, q.z);
      for (size_t i = 0; i < mesh.positions.size(); ++i) {
        EXPECT_NEAR(mesh.uvs[i].x, (mesh.positions[i].x - west) / 8.0f, 1e-5f);
        EXPECT_NEAR(mesh.uvs[i].y, 1.0f - (mesh.positions[i].z - base) / 6.0f, 1e-5f);
      }
    }
    // The missing file: one counted warning and the checkerboard.
    ASSERT_EQ(st.import.missing_textures.size(), 1u);
    EXPECT_EQ(st.import.missing_textures[0].name, "textures/missing_roof.jpg");
    EXPECT_EQ(st.import.placeholder_materials, 1u);
    for (const auto& p : objectNamed(c, "b4")->parts) {
      const auto& m = c.scene.materials[p.material];
      if (m.name == "textures/missing_roof.jpg") {
        EXPECT_TRUE(farfield::scene::TextureFiles::isPlaceholder(m.texture));
        EXPECT_TRUE(m.texture_path.empty());
        EXPECT_EQ(c.scene.meshes[p.mesh].uvs.size(), c.scene.meshes[p.mesh].positions.size());
      }
    }
  }

  // Theme "winter": b2's south wall takes texture 1 (the missing file), b4 has no texture in it.
  CityJsonImportOptions winter;
  winter.theme = "winter";
  const CityJsonScene w = importCityJson(dataFile("textured.city.json"), winter);
  EXPECT_EQ(w.stats.texture_theme, "winter");
  EXPECT_EQ(w.stats.material_theme, "summer");  // the only material theme
  EXPECT_EQ(w.stats.textured_surfaces, 1u);
  EXPECT_EQ(measureObject(w, *objectNamed(w, "b2")).count("textures/missing_roof.jpg"), 1u);
  EXPECT_EQ(measureObject(w, *objectNamed(w, "b4")).count("textures/missing_roof.jpg"), 0u);
  CityJsonImportOptions autumn;
  autumn.theme = "autumn";
  try {
    importCityJson(dataFile("textured.city.json"), autumn);
    ADD_FAILURE() << "no error for a theme the file does not have";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("summer, winter"), std::string::npos) << e.what();
  }

  // Texture references that do not fit: a uv index out of range, a ring with one uv too few. The faces are kept
  // with their class colour and counted.
  nlohmann::json doc;
  std::ifstream(dataFile("textured.city.json")) >> doc;
  doc["CityObjects"]["b2"]["geometry"][0]["texture"]["summer"]["values"][0][1][0][2] = 99;
  doc["CityObjects"]["b4"]["geometry"][0]["texture"]["summer"]["values"][0][1][0].erase(4);
  const auto dir = farfield::test::scratchDir("geodata_cityjson_textures");
  const std::string bad = (dir / "bad_refs.city.json").string();
  std::ofstream(bad) << doc.dump();
  const CityJsonScene b = importCityJson(bad);
  EXPECT_EQ(b.stats.bad_texture_references, 2u);
  EXPECT_EQ(b.stats.textured_surfaces, 0u);
  EXPECT_EQ(b.stats.triangles, 28u);
  EXPECT_EQ(measureObject(b, *objectNamed(b, "b2")).count("facade.png"), 0u);
}
