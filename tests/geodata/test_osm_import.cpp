// OpenStreetMap import: the hand-made small city (known blocks, heights, parts, courtyard), malformed files (one
// skip per reason), PBF written from the XML and then truncated or corrupted, and the Monaco extract.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include <osmium/io/any_input.hpp>
#include <osmium/io/any_output.hpp>

#include "farfield/core/error.h"
#include "farfield/core/polygon2d.h"
#include "farfield/core/timer.h"
#include "farfield/geodata/osm_import.h"
#include "farfield/geodata/projection.h"
#include "geodata/street_graph_checks.h"
#include "support/test_support.h"

using farfield::Error;
using farfield::Vec2;
using farfield::Vec3;
using farfield::geodata::importOsm;
using farfield::geodata::OsmCity;
using farfield::geodata::OsmImportOptions;

namespace {

std::string dataFile(const std::string& name) { return (farfield::test::testDataDir() / "geodata" / name).string(); }

const farfield::scene::Object* objectNamed(const OsmCity& c, const std::string& name) {
  for (const auto& o : c.city.scene.objects)
    if (o.name == name) return &o;
  return nullptr;
}

// Area of the triangles of an object's meshes whose normal points up (flat roofs), above z_min.
double upwardArea(const OsmCity& c, const farfield::scene::Object& o, float z_min) {
  double a = 0;
  for (const auto& part : o.parts) {
    const auto& m = c.city.scene.meshes[part.mesh];
    for (size_t i = 0; i < m.indices.size(); i += 3) {
      const Vec3 p0 = m.positions[m.indices[i]], p1 = m.positions[m.indices[i + 1]], p2 = m.positions[m.indices[i + 2]];
      const glm::dvec3 n = glm::cross(glm::dvec3(p1 - p0), glm::dvec3(p2 - p0));
      if (n.z > 0.99 * glm::length(n) && p0.z > z_min) a += 0.5 * glm::length(n);
    }
  }
  return a;
}

// Converts an OSM file to another format with osmium (test-side only).
void convert(const std::string& in, const std::string& out) {
  osmium::io::Reader reader{in};
  osmium::io::Header header;
  osmium::io::Writer writer{out, header, osmium::io::overwrite::allow};
  while (osmium::memory::Buffer buffer = reader.read()) writer(std::move(buffer));
  writer.close();
  reader.close();
}

std::string readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}
void writeBytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

// Metres per degree at the small city's latitude (43.73): spherical approximations good to ~0.5%.
constexpr double kLat = 43.7315;
const double kMetresPerDegLon = 111320.0 * std::cos(kLat * M_PI / 180.0);
constexpr double kMetresPerDegLat = 111130.0;

}  // namespace

TEST(OsmImport, SmallCityBlocksHeightsAndParts) {
  OsmImportOptions options;
  options.objects = farfield::gen::ObjectGrouping::Buildings;
  const OsmCity c = importOsm(dataFile("small_city.osm"), options);
  const auto& st = c.stats;
  EXPECT_EQ(c.reference.crs, "EPSG:32632");  // 7.42 E is in UTM zone 32
  EXPECT_TRUE(st.read_error.empty());
  EXPECT_EQ(st.buildings, 7u);  // 201-205, 208 and the multipolygon; building=no left out
  EXPECT_EQ(st.parts, 2u);
  EXPECT_EQ(st.outlines_replaced, 1u);
  EXPECT_EQ(st.default_height_used, 2u);  // 203 and 208
  EXPECT_EQ(st.outside_blocks, 1u);       // 208
  EXPECT_EQ(st.skippedTotal(), 0u);

  // 3 x 3 grid, the primary road splits the 3 middle blocks: 12 blocks; footway and tunnel left out.
  const auto& g = c.city.streets;
  EXPECT_EQ(g.blockCount(), 12u);
  EXPECT_EQ(g.componentCount(), 1u);
  farfield::test::checkStreetGraph(g);
  // Every block of the grid is ~80 x 111 m or a part of one.
  double total = 0;
  for (uint32_t f = 1; f < g.faceCount(); ++f) total += farfield::signedArea(g.facePolygon(f));
  EXPECT_NEAR(total, 9 * 0.001 * kMetresPerDegLon * 0.001 * kMetresPerDegLat, 0.01 * total);

  // Objects: ground + one per building (parts inside their outline's object).
  ASSERT_EQ(c.city.scene.objects.size(), 1u + 7u);
  EXPECT_EQ(c.city.scene.objects[0].name, "ground");
  ASSERT_EQ(c.city.object_block.size(), c.city.scene.objects.size());
  const std::map<std::string, float> tops = {{"way 201", 12.0f},  {"way 202", 18.0f},         {"way 203", 10.0f},
                                             {"relation 301", 20.0f}, {"way 204", 40 * 0.3048f}, {"way 205", 30.0f},
                                             {"way 208", 10.0f}};
  for (const auto& [name, top] : tops) {
    const auto* o = objectNamed(c, name);
    ASSERT_NE(o, nullptr) << name;
    EXPECT_NEAR(o->world_bounds.hi.z, top, 1e-4f) << name;
    EXPECT_NEAR(o->world_bounds.lo.z, 0.0f, 1e-4f) << name;
    // The block recorded for the object holds the footprint's centroid (checked with the block's polygon).
    const int32_t block = c.city.object_block[o->id - 1];
    const Vec2 centroid = farfield::polygonCentroid(o->footprint);
    if (name == "way 208") {
      EXPECT_EQ(block, -1);
    } else {
      ASSERT_GT(block, 0) << name;
      EXPECT_TRUE(farfield::pointInPolygon(centroid, g.facePolygon(uint32_t(block)))) << name;
    }
  }
  // Five buildings in five different blocks, 205 in the upper half of a split block (about 80 x 50 m).
  std::set<int32_t> blocks;
  for (const auto& [name, top] : tops)
    if (name != "way 208") blocks.insert(c.city.object_block[objectNamed(c, name)->id - 1]);
  EXPECT_EQ(blocks.size(), 6u);
  const int32_t b205 = c.city.object_block[objectNamed(c, "way 205")->id - 1];
  EXPECT_NEAR(farfield::signedArea(g.facePolygon(uint32_t(b205))),
              0.001 * kMetresPerDegLon * 0.00045 * kMetresPerDegLat, 0.02 * 4000.0);

  // The courtyard: the flat roof of relation 301 covers 3/4 of its outer footprint.
  const auto* courtyard = objectNamed(c, "relation 301");
  EXPECT_NEAR(upwardArea(c, *courtyard, 19.0f), 0.75 * std::abs(farfield::signedArea(courtyard->footprint)), 0.5);
  // The outline with parts: drawn as its two parts (two boxes, the east one raised to 10..20 m), 16 wall and
  // 2 + 2 roof triangles plus the 2 of the raised part's underside.
  const auto* outline = objectNamed(c, "way 205");
  size_t triangles = 0;
  float lowest_roof = 1e9f;
  for (const auto& part : outline->parts) {
    triangles += c.city.scene.meshes[part.mesh].triangleCount();
  }
  EXPECT_EQ(triangles, 22u);
  for (const auto& part : outline->parts)
    for (const Vec3& p : c.city.scene.meshes[part.mesh].positions)
      if (p.z > 0.5f) lowest_roof = std::min(lowest_roof, p.z);
  EXPECT_NEAR(lowest_roof, 10.0f, 1e-4f);

  // Blocks mode: one object per block holding buildings (6) and one tile for the building outside.
  const OsmCity blocks_city = importOsm(dataFile("small_city.osm"));
  EXPECT_EQ(blocks_city.city.scene.objects.size(), 1u + 6u + 1u);
  EXPECT_EQ(blocks_city.city.scene.triangleCount(), c.city.scene.triangleCount());

  // With footways selected, the diagonal footway splits one more block; with tunnels, one dead end more.
  OsmImportOptions more;
  more.read.highways = farfield::geodata::parseHighwayList("--highways", "residential,primary,footway");
  more.read.include_tunnels = true;
  const OsmCity m = importOsm(dataFile("small_city.osm"), more);
  EXPECT_EQ(m.city.streets.blockCount(), 13u);
  EXPECT_EQ(m.city.streets.streetCount(), g.streetCount() + 2u);  // the footway and the (unconnected) tunnel
  farfield::test::checkStreetGraph(m.city.streets);
}

TEST(OsmImport, BboxSelectsBuildingsAndStreets) {
  OsmImportOptions options;
  options.objects = farfield::gen::ObjectGrouping::Buildings;
  // The south row of the grid only (lat 43.7295..43.7312): buildings 201 and 202.
  options.read.bbox = farfield::geodata::parseLonLatBox("--bbox", "7.4195,43.7295,7.4235,43.7312");
  const OsmCity c = importOsm(dataFile("small_city.osm"), options);
  EXPECT_EQ(c.stats.buildings, 2u);
  EXPECT_EQ(c.stats.outside_bbox, 7u);  // 203, 204, 205, 206, 207, 208, 301
  EXPECT_EQ(c.city.streets.blockCount(), 3u);
  EXPECT_THROW(farfield::geodata::parseLonLatBox("--bbox", "1,2,3"), Error);
  EXPECT_THROW(farfield::geodata::parseLonLatBox("--bbox", "5,2,3,4"), Error);
  EXPECT_THROW(farfield::geodata::parseLonLatBox("--bbox", "1,2,3,x"), Error);
  EXPECT_THROW(farfield::geodata::parseLonLatBox("--bbox", "-200,2,3,4"), Error);
  EXPECT_THROW(farfield::geodata::parseHighwayList("--highways", "residential,spaceway"), Error);
  // A box with no data in it.
  options.read.bbox = farfield::geodata::parseLonLatBox("--bbox", "10,10,10.1,10.1");
  EXPECT_THROW(importOsm(dataFile("small_city.osm"), options), Error);
}

TEST(OsmImport, MalformedBuildingsAreCountedPerReason) {
  const OsmCity c = importOsm(dataFile("malformed.osm"));
  const auto& st = c.stats;
  for (const auto& [reason, n] : st.skipped) std::printf("  skipped %-45s %zu\n", reason.c_str(), n);
  EXPECT_EQ(st.buildings, 1u);
  const std::map<std::string, size_t> expected = {{"missing nodes", 1},
                                                  {"unclosed ring", 1},
                                                  {"self-intersecting footprint", 1},
                                                  {"zero or tiny area", 1},
                                                  {"fewer than 3 distinct nodes", 1},
                                                  {"relation members missing from the file", 1}};
  EXPECT_EQ(st.skipped, expected);
  EXPECT_EQ(st.highway_ways, 2u);
  farfield::test::checkStreetGraph(c.city.streets);
}

TEST(OsmImport, UnsortedFileSaysSo) {
  // Ways out of id order: osmium stops at the first one; what was read before is imported, and the reason is
  // given with the remedy.
  const OsmCity c = importOsm(dataFile("unsorted.osm"));
  EXPECT_NE(c.stats.read_error.find("sorted"), std::string::npos) << c.stats.read_error;
  EXPECT_LT(c.stats.buildings, 7u);
}

TEST(OsmImport, NothingUsableNamesTheFile) {
  for (const char* name : {"all_bad.osm", "garbage.osm.pbf", "does_not_exist.osm.pbf"}) {
    const std::string path = dataFile(name);
    try {
      importOsm(path);
      ADD_FAILURE() << name << ": no error";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
      std::printf("  %s -> %s\n", name, e.what());
    }
  }
}

TEST(OsmImport, PbfTruncatedAndCorrupt) {
  const auto dir = farfield::test::scratchDir("geodata_pbf");
  const std::string pbf = (dir / "small_city.osm.pbf").string();
  convert(dataFile("small_city.osm"), pbf);
  OsmImportOptions options;
  options.objects = farfield::gen::ObjectGrouping::Buildings;
  const OsmCity whole = importOsm(pbf, options);
  EXPECT_EQ(whole.stats.buildings, 7u);
  EXPECT_EQ(whole.city.streets.blockCount(), 12u);

  // Truncations at many points, and corrupted bytes: either an Error naming the file or an import that says the
  // file broke (read_error) -- never a crash.
  const std::string bytes = readBytes(pbf);
  size_t errors = 0, partial = 0;
  for (size_t cut : {size_t(0), size_t(5), size_t(20), bytes.size() / 4, bytes.size() / 2, bytes.size() - 10,
                     bytes.size() - 1}) {
    const std::string path = (dir / ("cut_" + std::to_string(cut) + ".osm.pbf")).string();
    writeBytes(path, bytes.substr(0, cut));
    try {
      const OsmCity c = importOsm(path, options);
      EXPECT_FALSE(c.stats.read_error.empty()) << "cut at " << cut;
      ++partial;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
      ++errors;
    }
  }
  EXPECT_GT(errors, 0u);
  for (size_t at : {bytes.size() / 3, bytes.size() / 2, 2 * bytes.size() / 3}) {
    std::string bad = bytes;
    for (size_t k = at; k < std::min(bad.size(), at + 16); ++k) bad[k] = char(bad[k] ^ 0x5a);
    const std::string path = (dir / ("corrupt_" + std::to_string(at) + ".osm.pbf")).string();
    writeBytes(path, bad);
    try {
      const OsmCity c = importOsm(path, options);
      EXPECT_FALSE(c.stats.read_error.empty());
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  }
  std::printf("  truncated PBF: %zu errors, %zu partial imports\n", errors, partial);
}

TEST(OsmImport, Monaco) {
  FF_SHARED_FILE_OR_SKIP(pbf, "city/monaco-2016.osm.pbf");
  const std::string path = pbf.string();
  farfield::Stopwatch clock;
  const OsmCity c = importOsm(path);
  const double seconds = clock.seconds();
  const auto& st = c.stats;
  std::printf("  monaco: %zu buildings, %zu parts (%zu outlines replaced), %zu default height, %zu outside blocks\n",
              st.buildings, st.parts, st.outlines_replaced, st.default_height_used, st.outside_blocks);
  for (const auto& [reason, n] : st.skipped) std::printf("  skipped %-45s %zu\n", reason.c_str(), n);
  std::printf("  streets: %zu junctions, %zu streets, %zu blocks, %zu components (%zu crossings split, %zu merged, "
              "%zu snapped)\n",
              c.city.streets.junctionCount(), c.city.streets.streetCount(), c.city.streets.blockCount(),
              c.city.streets.componentCount(), st.streets.crossings, st.streets.merged_points,
              st.streets.snapped_to_junction);
  std::printf("  scene: %zu objects, %llu triangles; %.2f s (read %.2f, build %.2f, streets %.2f, assign %.2f)\n",
              c.city.scene.objects.size(), (unsigned long long)c.city.scene.triangleCount(), seconds, st.read_s,
              st.build_s, st.streets_s, st.assign_s);
  EXPECT_TRUE(st.read_error.empty());
  EXPECT_GE(st.buildings, 20000u);
  EXPECT_EQ(c.reference.crs, "EPSG:32632");
  EXPECT_GT(c.city.streets.blockCount(), 100u);
  EXPECT_EQ(st.streets.unresolved, 0u);
  farfield::test::checkStreetGraph(c.city.streets);
  c.city.scene.validate("monaco");
  // Block objects' footprints are their block polygons.
  for (size_t i = 1; i < c.city.scene.objects.size(); ++i) {
    const int32_t block = c.city.object_block[i];
    if (block > 0) {
      EXPECT_NEAR(farfield::signedArea(c.city.scene.objects[i].footprint),
                  farfield::signedArea(c.city.streets.facePolygon(uint32_t(block))), 1e-3);
    }
  }
  // Local coordinates stay within a few km of the origin (float precision).
  const auto b = c.city.scene.bounds();
  EXPECT_LT(std::max(std::abs(b.lo.x), std::abs(b.hi.x)), 10000.0f);
  EXPECT_LT(std::max(std::abs(b.lo.y), std::abs(b.hi.y)), 10000.0f);
}

TEST(OsmImport, MonacoBuildingBlocksBruteForce) {
  // Per building: the recorded block is the smallest face holding the footprint's centroid, checked by brute force
  // over every face on a sample of buildings; buildings in no block are in none of the faces.
  FF_SHARED_FILE_OR_SKIP(pbf, "city/monaco-2016.osm.pbf");
  const std::string path = pbf.string();
  OsmImportOptions options;
  options.objects = farfield::gen::ObjectGrouping::Buildings;
  options.ground = false;
  const OsmCity c = importOsm(path, options);
  const auto& g = c.city.streets;
  std::vector<farfield::Polygon2> faces(g.faceCount());
  for (uint32_t f = 1; f < g.faceCount(); ++f) faces[f] = g.facePolygon(f);
  size_t checked = 0, outside = 0;
  for (size_t i = 0; i < c.city.scene.objects.size(); i += 37) {
    const auto& o = c.city.scene.objects[i];
    const Vec2 centroid = farfield::polygonCentroid(o.footprint);
    int32_t expected = -1;
    double expected_area = 0.0;
    for (uint32_t f = 1; f < g.faceCount(); ++f) {
      if (!farfield::pointInPolygon(centroid, faces[f])) continue;
      const double a = farfield::signedArea(faces[f]);
      if (expected < 0 || a < expected_area) expected = int32_t(f), expected_area = a;
    }
    EXPECT_EQ(c.city.object_block[i], expected) << o.name;
    ++checked;
    outside += expected < 0;
  }
  std::printf("  checked %zu buildings by brute force, %zu in no block\n", checked, outside);
  EXPECT_GT(checked, 500u);
}

TEST(OsmImport, MonacoTruncated) {
  // The real file cut at 99% (in its ways: the nodes fill the first ~97%): what was read before the cut is
  // imported and the break is reported.
  FF_SHARED_FILE_OR_SKIP(pbf, "city/monaco-2016.osm.pbf");
  const std::string path = pbf.string();
  const std::string bytes = readBytes(path);
  const std::string cut = (farfield::test::scratchDir("geodata_monaco_cut") / "monaco_cut.osm.pbf").string();
  writeBytes(cut, bytes.substr(0, bytes.size() * 99 / 100));
  const OsmCity c = importOsm(cut);
  std::printf("  truncated at 99%%: %zu buildings, %zu streets; %s\n", c.stats.buildings, c.city.streets.streetCount(),
              c.stats.read_error.c_str());
  EXPECT_FALSE(c.stats.read_error.empty());
  EXPECT_GT(c.stats.buildings + c.city.streets.streetCount(), 0u);
}
