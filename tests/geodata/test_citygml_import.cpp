// CityGML import: hand-made CityGML 1.0 and 2.0 cities (tests/data/geodata/make_appearance_files.py) with areas,
// volumes and triangle counts computed by hand, textures and materials, LoD choice, a city with roads whose street
// graph and blocks are known, and malformed documents that must give an error naming the file.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "farfield/core/error.h"
#include "farfield/core/polygon2d.h"
#include "farfield/geodata/citygml_import.h"
#include "support/test_support.h"

using farfield::Error;
using farfield::Vec4;
using farfield::geodata::CityGmlImportOptions;
using farfield::geodata::CityGmlScene;
using farfield::geodata::importCityGml;
using farfield::geodata::importCityGmlText;

namespace {

std::string dataFile(const std::string& name) { return (farfield::test::testDataDir() / "geodata" / name).string(); }

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

const farfield::scene::Object* objectNamed(const CityGmlScene& c, const std::string& name) {
  for (const auto& o : c.city.scene.objects)
    if (o.name == name) return &o;
  return nullptr;
}

struct Measures {
  double area = 0.0;
  double volume = 0.0;  // signed (divergence theorem): positive for closed, outward surfaces
  size_t triangles = 0;
};

Measures measure(const farfield::scene::Mesh& m) {
  Measures r;
  for (size_t i = 0; i + 2 < m.indices.size(); i += 3) {
    const glm::dvec3 a(m.positions[m.indices[i]]), b(m.positions[m.indices[i + 1]]), c(m.positions[m.indices[i + 2]]);
    r.area += 0.5 * glm::length(glm::cross(b - a, c - a));
    r.volume += glm::dot(a, glm::cross(b, c)) / 6.0;
    ++r.triangles;
  }
  return r;
}

Measures measureObject(const CityGmlScene& c, const farfield::scene::Object& o) {
  Measures r;
  for (const auto& p : o.parts) {
    const Measures m = measure(c.city.scene.meshes[p.mesh]);
    r.area += m.area, r.volume += m.volume, r.triangles += m.triangles;
  }
  return r;
}

void expectError(const std::function<void()>& f, const std::vector<std::string>& needles) {
  try {
    f();
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    const std::string what = e.what();
    for (const std::string& n : needles) EXPECT_NE(what.find(n), std::string::npos) << "'" << n << "' not in: " << what;
    std::printf("  %s\n", what.c_str());
  }
}

const double kRoof = 2.0 * 8.0 * std::sqrt(18.0);  // b2's two roof faces: 8 m by sqrt(3^2 + 3^2)

}  // namespace

TEST(CityGmlImport, BuildingsPartsLodsAndAppearancesHandComputed) {
  for (const char* name : {"citygml2_city.gml", "citygml1_city.gml"}) {
    SCOPED_TRACE(name);
    const CityGmlScene c = importCityGml(dataFile(name));
    const auto& st = c.stats;
    for (const auto& [reason, n] : st.skipped) std::printf("  skipped %-50s %zu\n", reason.c_str(), n);
    EXPECT_EQ(st.version, std::string(name).find("citygml2") == 0 ? "2.0" : "1.0");
    EXPECT_EQ(st.crs, "EPSG:25832");
    EXPECT_EQ(st.city_objects, 4u);
    EXPECT_EQ(st.buildings, 4u);
    EXPECT_EQ(st.building_parts, 2u);
    EXPECT_EQ(st.skippedTotal(), 0u);
    EXPECT_EQ(st.lods, (std::map<unsigned, size_t>{{1u, 3u}, {2u, 1u}}));
    // Faces: b1 6, b2 7 (semantic), b3 2 x 6, b4 6. Triangles: quads 2, b2's gable pentagons 3.
    EXPECT_EQ(st.surfaces, 31u);
    EXPECT_EQ(st.semantic_surfaces, 7u);
    EXPECT_EQ(st.inferred_surfaces, 24u);
    EXPECT_EQ(st.triangles, 12u + 16u + 24u + 12u);
    // No roads: no street graph, one object per building.
    EXPECT_EQ(c.city.streets.streetCount(), 0u);
    ASSERT_EQ(c.city.scene.objects.size(), 4u);
    EXPECT_EQ(c.city.object_block, (std::vector<int32_t>{-1, -1, -1, -1}));
    EXPECT_NO_THROW(c.city.scene.validate(name));

    // Origin: the centre of x 0..65, y 0..10 (+ 690000, 5336000), rounded; z kept.
    EXPECT_DOUBLE_EQ(c.reference.origin.x, 690033.0);
    EXPECT_DOUBLE_EQ(c.reference.origin.y, 5336005.0);
    EXPECT_DOUBLE_EQ(c.reference.origin.z, 0.0);
    EXPECT_NEAR(c.file_min.z, 500.0, 1e-9);
    EXPECT_NEAR(c.file_max.z, 512.0, 1e-9);
    const auto b = c.city.scene.bounds();
    EXPECT_NEAR(b.lo.x, -33.0f, 1e-3f);
    EXPECT_NEAR(b.hi.x, 32.0f, 1e-3f);
    EXPECT_NEAR(b.lo.y, -5.0f, 1e-3f);
    EXPECT_NEAR(b.hi.y, 5.0f, 1e-3f);

    // Areas and volumes by hand; every building closed and outward.
    struct Expect {
      const char* id;
      double area, volume;
      size_t triangles;
    };
    for (const Expect& e : {Expect{"b1", 600.0, 1000.0, 12}, Expect{"b2", 48.0 + 96.0 + 90.0 + kRoof, 288.0 + 72.0, 16},
                            Expect{"b3", 216.0 + 224.0, 216.0 + 192.0, 24}, Expect{"b4", 110.0, 75.0, 12}}) {
      SCOPED_TRACE(e.id);
      const auto* o = objectNamed(c, e.id);
      ASSERT_NE(o, nullptr);
      const Measures m = measureObject(c, *o);
      EXPECT_NEAR(m.area, e.area, 1e-3);
      EXPECT_NEAR(m.volume, e.volume, 1e-2);
      EXPECT_EQ(m.triangles, e.triangles);
    }

    // Appearances of theme "rgbTexture": b2's south wall textured, its roof in the X3DMaterial's colour, b4's
    // roof a missing file (a counted warning and the checkerboard).
    EXPECT_EQ(st.themes, std::vector<std::string>{"rgbTexture"});
    EXPECT_EQ(st.theme, "rgbTexture");
    EXPECT_EQ(st.textured_surfaces, 2u);
    EXPECT_EQ(st.material_surfaces, 2u);
    EXPECT_EQ(st.bad_texture_coordinates, 0u);
    ASSERT_EQ(st.import.missing_textures.size(), 1u);
    EXPECT_EQ(st.import.missing_textures[0].name, "textures/missing_roof.jpg");
    bool facade = false, roof = false, placeholder = false;
    for (const char* id : {"b2", "b4"})
      for (const auto& p : objectNamed(c, id)->parts) {
        const auto& mat = c.city.scene.materials[p.material];
        const auto& mesh = c.city.scene.meshes[p.mesh];
        if (mat.name == "facade.png") {
          facade = true;
          ASSERT_TRUE(mat.texture);
          ASSERT_EQ(mat.texture->width(), 4);
          EXPECT_EQ(mat.texture->at(1, 0), farfield::image::Rgba8(0, 255, 0, 255));
          EXPECT_NEAR(measure(mesh).area, 48.0, 1e-3);
          // The file maps u = (x - west) / 8, v = height / 6 from the bottom; Farfield's v runs from the top.
          ASSERT_EQ(mesh.uvs.size(), mesh.positions.size());
          float west = 1e9f, base = 1e9f;
          for (const auto& q : mesh.positions) west = std::min(west, q.x), base = std::min(base, q.z);
          for (size_t i = 0; i < mesh.positions.size(); ++i) {
            EXPECT_NEAR(mesh.uvs[i].x, (mesh.positions[i].x - west) / 8.0f, 1e-5f);
            EXPECT_NEAR(mesh.uvs[i].y, 1.0f - (mesh.positions[i].z - base) / 6.0f, 1e-5f);
          }
        } else if (mat.base_color == Vec4(0.8f, 0.2f, 0.1f, 1.0f) && !mat.texture) {
          roof = true;
          EXPECT_NEAR(measure(mesh).area, kRoof, 1e-3);
        } else if (mat.name == "textures/missing_roof.jpg") {
          placeholder = true;
          EXPECT_TRUE(farfield::scene::TextureFiles::isPlaceholder(mat.texture));
          EXPECT_NEAR(measure(mesh).area, 25.0, 1e-3);
        }
      }
    EXPECT_TRUE(facade && roof && placeholder);
  }
}

TEST(CityGmlImport, LodChoiceAndThemes) {
  CityGmlImportOptions lod1;
  lod1.max_lod = 1;
  const CityGmlScene c = importCityGml(dataFile("citygml2_city.gml"), lod1);
  EXPECT_EQ(c.city.scene.objects.size(), 3u);  // b2 has LoD2 only
  EXPECT_EQ(c.stats.skipped.at("objects without geometry at the requested LoD"), 1u);
  EXPECT_EQ(c.stats.triangles, 12u + 24u + 12u);
  CityGmlImportOptions unknown;
  unknown.theme = "winter";
  expectError([&] { importCityGml(dataFile("citygml2_city.gml"), unknown); },
              {"citygml2_city.gml", "no appearance theme 'winter'", "rgbTexture"});
  // The same document from memory, its textures found next to where it would be.
  const CityGmlScene m = importCityGmlText(readFile(dataFile("citygml2_city.gml")), "memory.gml",
                                           (farfield::test::testDataDir() / "geodata").string());
  EXPECT_EQ(m.stats.triangles, 64u);
  EXPECT_TRUE(m.stats.import.missing_textures.size() == 1u);
}

TEST(CityGmlImport, RoadsMakeTheStreetGraphAndBlocks) {
  // Roads 10 m wide on x, y = 0, 110, 220 around 4 blocks; a 20 x 20 x 15 building in each block, two in the
  // south-west one (area of each box 2 x 400 + 4 x 300 = 2000 m^2, volume 6000 m^3).
  const CityGmlScene c = importCityGml(dataFile("citygml2_streets.gml"));
  const auto& st = c.stats;
  EXPECT_EQ(st.road_objects, 6u);
  EXPECT_EQ(st.buildings, 5u);
  EXPECT_EQ(st.ground_objects, 6u);
  EXPECT_EQ(st.outside_blocks, 0u);
  const auto& g = c.city.streets;
  ASSERT_EQ(g.blockCount(), 4u);
  for (uint32_t f = 1; f < g.faceCount(); ++f)
    EXPECT_NEAR(std::abs(farfield::signedArea(g.facePolygon(f))), 110.0 * 110.0, 1.0);
  // Object 1 is the ground (the six road rectangles, 10 x 230 each), then one object per block.
  ASSERT_EQ(c.city.scene.objects.size(), 5u);
  EXPECT_EQ(c.city.scene.objects[0].name, "ground");
  EXPECT_NEAR(measureObject(c, c.city.scene.objects[0]).area, 6.0 * 10.0 * 230.0, 1e-2);
  ASSERT_EQ(c.city.object_block.size(), 5u);
  EXPECT_EQ(c.city.object_block[0], -1);
  double total = 0.0;
  for (size_t i = 1; i < 5; ++i) {
    const auto& o = c.city.scene.objects[i];
    const Measures m = measureObject(c, o);
    total += m.area;
    EXPECT_GE(c.city.object_block[i], 1);
    // The block's footprint holds the object's buildings.
    EXPECT_TRUE(farfield::pointInPolygon(farfield::Vec2(o.world_bounds.center()), o.footprint)) << o.name;
    // Which block holds two buildings: the one whose polygon contains the south-west corner's building.
    const bool south_west = farfield::pointInPolygon(farfield::Vec2(-c.reference.origin.x + 690025.0,
                                                                    -c.reference.origin.y + 5336025.0),
                                                     g.facePolygon(uint32_t(c.city.object_block[i])));
    EXPECT_NEAR(m.area, south_west ? 4000.0 : 2000.0, 1e-2) << o.name;
    EXPECT_NEAR(m.volume, south_west ? 12000.0 : 6000.0, 1e-1) << o.name;
  }
  EXPECT_NEAR(total, 10000.0, 1e-2);
  // One object per building instead.
  CityGmlImportOptions per_building;
  per_building.objects = farfield::gen::ObjectGrouping::Buildings;
  const CityGmlScene b = importCityGml(dataFile("citygml2_streets.gml"), per_building);
  EXPECT_EQ(b.city.scene.objects.size(), 1u + 5u);
  EXPECT_EQ(b.city.streets.blockCount(), 4u);
}

TEST(CityGmlImport, MalformedDocumentsNameTheFile) {
  expectError([] { importCityGml(dataFile("citygml2_truncated.gml")); }, {"citygml2_truncated.gml", "line"});
  expectError([] { importCityGml(dataFile("no_such_city.gml")); }, {"no_such_city.gml", "not found"});
  const auto dir = farfield::test::scratchDir("geodata_citygml");
  auto write = [&](const std::string& name, const std::string& text) {
    const std::string p = (dir / name).string();
    std::ofstream(p, std::ios::binary) << text;
    return p;
  };
  expectError([&] { importCityGml(write("garbage.gml", "not xml at all")); }, {"garbage.gml"});
  expectError([&] { importCityGml(write("empty.gml", "")); }, {"empty.gml", "empty"});
  expectError([&] { importCityGml(write("other.gml", "<?xml version=\"1.0\"?><foo><bar/></foo>")); },
              {"other.gml", "no CityGML CityModel"});
  const std::string city = readFile(dataFile("citygml2_city.gml"));
  // Every truncation point in a sample of them gives an error or a smaller city, never a crash.
  for (size_t cut = 1; cut < city.size(); cut += city.size() / 23) {
    try {
      importCityGmlText(city.substr(0, cut), "cut.gml", dir.string());
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("cut.gml"), std::string::npos) << e.what();
    }
  }
  // Degrees are not metres; CityGML 3.0 is another schema.
  std::string geographic = city;
  geographic.replace(geographic.find("EPSG:25832"), 10, "EPSG:4326");
  expectError([&] { importCityGml(write("degrees.gml", geographic)); }, {"degrees.gml", "geographic", "EPSG:4326"});
  std::string v3 = city;
  for (size_t p; (p = v3.find("citygml/2.0")) != std::string::npos;) v3.replace(p, 11, "citygml/3.0");
  expectError([&] { importCityGml(write("v3.gml", v3)); }, {"v3.gml", "CityGML 3.0"});
  // A model without a single usable polygon.
  expectError([&] {
    importCityGml(write("no_geometry.gml", "<?xml version=\"1.0\"?><core:CityModel xmlns:core=\"http://www.opengis.net/"
                                           "citygml/2.0\" xmlns:bldg=\"http://www.opengis.net/citygml/building/2.0\" "
                                           "xmlns:gml=\"http://www.opengis.net/gml\"><core:cityObjectMember>"
                                           "<bldg:Building gml:id=\"x\"/></core:cityObjectMember></core:CityModel>"));
  }, {"no_geometry.gml", "no usable surface"});
}
