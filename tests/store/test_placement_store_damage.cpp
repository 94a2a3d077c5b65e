// Placement database damage: every truncation and byte flip of every file, digit changes, images of the wrong size
// and every kind of damage to the index give a farfield::Error naming the file and the record or element; the
// writer refuses a bad index before writing anything.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <functional>
#include <random>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/image/png_io.h"
#include "farfield/store/placement_store.h"
#include "store/placement_store_fixture.h"
#include "support/test_support.h"

namespace fs = std::filesystem;

namespace farfield::store {
namespace {

using placement_test::Content;
using placement_test::expectError;
using placement_test::makeContent;
using placement_test::namedFiles;
using placement_test::readBytes;
using placement_test::storedContent;
using placement_test::writeBytes;
using placement_test::writeDatabase;

TEST(PlacementStoreIntegrityTest, EveryTruncationAndByteFlipOfEveryFileIsAnErrorNamingFileAndRecord) {
  const std::string dir = test::scratchDir("placement_damage").string();
  const Content c = makeContent(11, {2, 5, 9}, 1);  // a small index: each of its bytes is damaged in turn
  writeDatabase(dir, c);
  const PlacementIndex index = readPlacementIndex(dir);
  struct Target {
    std::string name;    // relative to dir
    std::string record;  // what the message must name besides the file
    std::function<void()> load;
  };
  std::vector<Target> targets{{kPlacementIndexFile, "", [&] { readPlacementIndex(dir); }}};
  for (const StoredPlacedImpostor& s : index.impostors)
    for (size_t l = 0; l < s.layers.size(); ++l) {
      const std::string at = s.record + " layer " + std::to_string(l);
      const auto load = [&dir, &s] { loadPlacedImpostor(dir, s); };
      targets.push_back({s.layers[l].texture, at + " texture", load});
      if (!s.layers[l].ids.empty()) targets.push_back({s.layers[l].ids, at + " ids", load});
    }
  std::set<std::string> covered;
  for (const Target& t : targets) covered.insert(t.name);
  EXPECT_EQ(covered, namedFiles(index));

  size_t cases = 0;
  for (const Target& t : targets) {
    const std::string file = (fs::path(dir) / t.name).string();
    const std::string good = readBytes(file);
    const size_t n = good.size();
    ASSERT_GT(n, 2u) << t.name;
    const bool index_file = t.name == kPlacementIndexFile;
    const auto expect_found = [&](const std::string& bytes, const std::string& what, const std::string& how) {
      writeBytes(file, bytes);
      std::vector<std::string> parts{file, what};
      if (!t.record.empty()) parts.push_back(t.record);
      expectError(t.load, parts, t.name + ": " + how);
      ++cases;
    };
    for (size_t keep = 0; keep < n; ++keep)
      expect_found(good.substr(0, keep),
                   index_file ? "" : "truncated: " + std::to_string(keep) + " of " + std::to_string(n) + " bytes",
                   "truncation to " + std::to_string(keep) + " bytes");
    // A flip of every byte of the layer files, and of a thousand spread over the index (its checksum and text form
    // catch any: the index's own test below flips every digit).
    std::mt19937 rng{uint32_t(n)};
    const size_t step = std::max<size_t>(1, n / 1000);
    for (size_t at = 0; at < n; at += index_file ? step : 1) {
      std::string bad = good;
      bad[at] = char(uint8_t(bad[at]) ^ uint8_t(1u << (rng() % 8)));
      expect_found(bad, index_file ? "" : "checksum mismatch", "flip of byte " + std::to_string(at));
    }
    expect_found(good + "\n", index_file ? "" : "too long", "one byte appended");
    writeBytes(file, good);
    EXPECT_NO_THROW(t.load()) << t.name;
  }
  EXPECT_GT(cases, 10000u);
  EXPECT_EQ(storedContent(dir), [&] {
    const std::string other = test::scratchDir("placement_damage_fresh").string();
    writeDatabase(other, c);
    return storedContent(other);
  }());
  // A missing file names itself and the record.
  const StoredPlacedImpostor& s = index.impostors[0];
  fs::remove(fs::path(dir) / s.layers[0].texture);
  expectError([&] { loadPlacedImpostor(dir, s); }, {s.layers[0].texture, s.record + " layer 0 texture", "cannot open"},
              "missing texture");
  expectError([&] { placementBytes(dir, index); }, {s.layers[0].texture}, "missing texture (bytes)");
}

TEST(PlacementStoreIntegrityTest, DigitChangesInTheIndexAreCaughtByItsChecksum) {
  // A digit changed for another leaves valid JSON of the same layout: only the checksum can see it.
  const std::string dir = test::scratchDir("placement_digits").string();
  writeDatabase(dir, makeContent(13, {2, 5, 9}, 1));
  const std::string file = (fs::path(dir) / kPlacementIndexFile).string();
  const std::string good = readBytes(file);
  size_t digits = 0;
  for (size_t at = 0; at < good.size(); ++at) {
    if (good[at] < '0' || good[at] > '8') continue;
    std::string bad = good;
    ++bad[at];
    writeBytes(file, bad);
    try {
      readPlacementIndex(dir);
      ADD_FAILURE() << "digit at " << at << " changed without an error";
    } catch (const Error& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(file), std::string::npos) << msg;
      // (A digit of "checksum" itself may push it past 32 bits, which its own check names.)
      EXPECT_TRUE(msg.find("checksum mismatch") != std::string::npos ||
                  msg.find("\"checksum\" must be a CRC-32") != std::string::npos ||
                  msg.find("text the placement writer") != std::string::npos ||
                  msg.find("not valid JSON") != std::string::npos)
          << msg;
    }
    ++digits;
  }
  EXPECT_GT(digits, 1000u);
  writeBytes(file, good);
  EXPECT_NO_THROW(readPlacementIndex(dir));
}

TEST(PlacementStoreIntegrityTest, ImagesOfTheWrongSizeAreRefusedNamingFileAndRecord) {
  // A layer file replaced by a valid PNG of another size, with the index's check updated: only the plan can tell.
  const std::string dir = test::scratchDir("placement_wrong_size").string();
  writeDatabase(dir, makeContent(5));
  PlacementIndex index = readPlacementIndex(dir);
  StoredPlacedImpostor& s = index.impostors[0];
  ASSERT_FALSE(s.layers[0].ids.empty());
  for (const bool ids : {false, true}) {
    std::string& name = ids ? s.layers[0].ids : s.layers[0].texture;
    FileCheck& check = ids ? s.layers[0].ids_check : s.layers[0].texture_check;
    const std::string file = (fs::path(dir) / name).string();
    const std::string good = readBytes(file);
    const FileCheck good_check = check;
    const std::string scratch = file + ".other.png";
    image::writePng(scratch, image::ColorImage(13, 1));  // wider than any layer (max_texture_size <= 12)
    writeBytes(file, readBytes(scratch));
    fs::remove(scratch);
    check = fileCheck(readBytes(file));
    expectError([&] { loadPlacedImpostor(dir, s); },
                {file, s.record + " layer 0 " + (ids ? "ids" : "texture"), "13x1 but the plan needs"}, name);
    writeBytes(file, good);
    check = good_check;
    EXPECT_NO_THROW(loadPlacedImpostor(dir, s));
  }
}

TEST(PlacementStoreIntegrityTest, DamagedIndexGivesErrorsNamingTheElement) {
  const std::string dir = test::scratchDir("placement_bad_index").string();
  // A fixed view space: node 0 splits into 1 (leaf: CPVs 0, 1) and 2, which splits into 3 (leaf: CPV 2) and 4
  // (leaf: CPVs 3, 4). Impostors 2, 5 and 9.
  Content c = makeContent(9);
  PlacementIndex& v = c.index;
  v.view_space = Box3::fromPoints(Vec3(0.0f), Vec3(100.0f, 50.0f, 10.0f));
  const Box3 left = Box3::fromPoints(Vec3(0.0f), Vec3(50.0f, 50.0f, 10.0f));
  const Box3 right = Box3::fromPoints(Vec3(50.0f, 0.0f, 0.0f), Vec3(100.0f, 50.0f, 10.0f));
  const Box3 right_lo = Box3::fromPoints(Vec3(50.0f, 0.0f, 0.0f), Vec3(100.0f, 25.0f, 10.0f));
  const Box3 right_hi = Box3::fromPoints(Vec3(50.0f, 25.0f, 0.0f), Vec3(100.0f, 50.0f, 10.0f));
  v.nodes = {{v.view_space, {1, 2}, 0, 5, false, {}}, {left, {-1, -1}, 0, 2, false, {}},
             {right, {3, 4}, 2, 3, false, {}}, {right_lo, {-1, -1}, 2, 1, false, {}},
             {right_hi, {-1, -1}, 3, 2, false, {}}};
  const auto cpv = [](const Box3& region, int face, std::vector<uint32_t> imps) {
    return StoredCpv{region, Vdi::fullFace(face), 20.5, 12.25, std::move(imps)};
  };
  v.cpvs = {cpv(left, 0, {2, 5}), cpv(left, 1, {9}), cpv(right_lo, 2, {}), cpv(right_hi, 3, {2, 5, 9}),
            cpv(right_hi, 4, {5})};
  writeDatabase(dir, c);
  const std::string file = (fs::path(dir) / kPlacementIndexFile).string();
  const std::string good_text = readBytes(file);
  const nlohmann::json good = nlohmann::json::parse(good_text);
  ASSERT_NO_THROW(readPlacementIndex(dir));
  ASSERT_TRUE(good["impostors"][0]["options"]["id_textures"].get<bool>());
  ASSERT_FALSE(good["impostors"][1]["options"]["id_textures"].get<bool>());

  using Edit = std::function<void(nlohmann::json&)>;
  const std::vector<std::tuple<std::string, Edit, std::vector<std::string>>> cases{
      {"unknown top-level member", [](nlohmann::json& j) { j["extra"] = 1; },
       {"top level", "unknown member \"extra\""}},
      {"missing cpvs", [](nlohmann::json& j) { j.erase("cpvs"); }, {"top level", "missing \"cpvs\""}},
      {"wrong format", [](nlohmann::json& j) { j["format"] = "farfield-impostor-store"; }, {"\"format\""}},
      {"newer version", [](nlohmann::json& j) { j["version"] = 4; }, {"unsupported version 4"}},
      {"older version (layers not cropped)", [](nlohmann::json& j) { j["version"] = 1; }, {"unsupported version 1"}},
      {"older version (texels per impostor)", [](nlohmann::json& j) { j["version"] = 2; }, {"unsupported version 2"}},
      {"generation 0", [](nlohmann::json& j) { j["generation"] = 0; }, {"\"generation\"", ">= 1"}},
      {"scene_objects a string", [](nlohmann::json& j) { j["scene_objects"] = "many"; },
       {"\"scene_objects\" must be a non-negative integer"}},
      {"view space as an array", [](nlohmann::json& j) { j["view_space"] = {1, 2}; },
       {"view_space", "expected an object"}},
      {"unknown impostor member", [](nlohmann::json& j) { j["impostors"][1]["color"] = 1; },
       {"impostors[1]", "unknown member \"color\""}},
      {"object id 0", [](nlohmann::json& j) { j["impostors"][1]["objects"][0] = 0; },
       {"impostors[1]", "\"objects\" holds an id outside 1..40"}},
      {"object id past the scene", [](nlohmann::json& j) { j["impostors"][2]["objects"].push_back(41); },
       {"impostors[2]", "outside 1..40"}},
      {"objects not ascending", [](nlohmann::json& j) { j["impostors"][0]["objects"] = {7, 3}; },
       {"impostors[0]", "ascending"}},
      {"no objects", [](nlohmann::json& j) { j["impostors"][0]["objects"] = nlohmann::json::array(); },
       {"impostors[0]", "\"objects\" is empty"}},
      {"impostor ids not ascending", [](nlohmann::json& j) { j["impostors"][1]["id"] = 2; },
       {"impostors[1].id", "sorted by id"}},
      {"negative id", [](nlohmann::json& j) { j["impostors"][0]["id"] = -2; }, {"impostors[0]", "\"id\""}},
      {"cpv names a missing impostor", [](nlohmann::json& j) { j["cpvs"][3]["impostors"][1] = 6; },
       {"cpvs[3].impostors[1]", "names impostor 6, which the index does not hold"}},
      {"cpv impostors repeated", [](nlohmann::json& j) { j["cpvs"][3]["impostors"][1] = 2; },
       {"cpvs[3].impostors[1]", "ascending without repeats"}},
      {"cpv impostor id negative", [](nlohmann::json& j) { j["cpvs"][0]["impostors"][0] = -1; },
       {"cpvs[0].impostors[0]", "must be an impostor id"}},
      {"cpv impostor id a string", [](nlohmann::json& j) { j["cpvs"][4]["impostors"][0] = "5"; },
       {"cpvs[4].impostors[0]"}},
      {"vdi face 6", [](nlohmann::json& j) { j["cpvs"][2]["vdi"]["face"] = 6; },
       {"cpvs[2].vdi", "\"face\" must be an integer in 0..5"}},
      {"vdi u0 > u1", [](nlohmann::json& j) { j["cpvs"][2]["vdi"]["u0"] = 1.0; },
       {"cpvs[2].vdi", "-1 <= u0 < u1 <= 1"}},
      {"vdi v outside the face", [](nlohmann::json& j) { j["cpvs"][2]["vdi"]["v1"] = 1.5; },
       {"cpvs[2].vdi", "-1 <= v0 < v1 <= 1"}},
      {"vdi not a number", [](nlohmann::json& j) { j["cpvs"][1]["vdi"]["u0"] = "left"; },
       {"cpvs[1].vdi", "\"u0\" must be a number"}},
      {"unknown vdi member", [](nlohmann::json& j) { j["cpvs"][1]["vdi"]["level"] = 3; },
       {"cpvs[1].vdi", "unknown member \"level\""}},
      {"negative time", [](nlohmann::json& j) { j["cpvs"][0]["t_enc"] = -1.0; }, {"cpvs[0]", "\"t_enc\" must be >= 0"}},
      {"time a string", [](nlohmann::json& j) { j["cpvs"][0]["t_after"] = "fast"; },
       {"cpvs[0]", "\"t_after\" must be a number"}},
      {"empty region", [](nlohmann::json& j) { j["cpvs"][0]["region"]["lo"][0] = 60.0; },
       {"cpvs[0].region", "is empty"}},
      {"region outside its leaf", [](nlohmann::json& j) { j["cpvs"][2]["region"]["hi"][1] = 30.0; },
       {"cpvs[2].region", "outside the box of nodes[3]"}},
      {"a node its own child", [](nlohmann::json& j) { j["nodes"][0]["children"] = {0, 2}; },
       {"nodes[0].children", "both nodes after it"}},
      {"a child past the nodes", [](nlohmann::json& j) { j["nodes"][2]["children"][1] = 99; },
       {"nodes[2].children[1]", "node index"}},
      {"one child", [](nlohmann::json& j) { j["nodes"][2]["children"][1] = -1; }, {"nodes[2].children"}},
      {"three children", [](nlohmann::json& j) { j["nodes"][2]["children"].push_back(4); },
       {"nodes[2].children", "[lower, upper]"}},
      {"the same child twice", [](nlohmann::json& j) { j["nodes"][2]["children"] = {4, 4}; },
       {"nodes[2].children", "twice"}},
      {"a shared child", [](nlohmann::json& j) { j["nodes"][1]["children"] = {3, 4}; },
       {"nodes[3]", "a child of both nodes[1] and nodes[2]"}},
      {"a node no one's child",
       [](nlohmann::json& j) {
         j["nodes"].push_back(j["nodes"][3]);
         j["nodes"][5]["cpv_count"] = 0;
       },
       {"nodes[5]", "no node's child"}},
      {"no nodes", [](nlohmann::json& j) { j["nodes"] = nlohmann::json::array(); }, {"\"nodes\"", "is empty"}},
      {"cpv range outside the list", [](nlohmann::json& j) { j["nodes"][4]["cpv_count"] = 7; },
       {"nodes[4]", "leave the 5 CPVs"}},
      {"root misses a cpv", [](nlohmann::json& j) { j["nodes"][0]["cpv_count"] = 4; },
       {"nodes[0]", "must hold every CPV"}},
      {"children do not split the range", [](nlohmann::json& j) { j["nodes"][3]["cpv_first"] = 3; },
       {"nodes[2]", "children's CPV ranges"}},
      {"a child box leaving its parent", [](nlohmann::json& j) { j["nodes"][3]["box"]["lo"][0] = 40.0; },
       {"nodes[3]", "leaves the box of its parent nodes[2]"}},
      {"root box not the view space", [](nlohmann::json& j) { j["view_space"]["hi"][2] = 11.0; },
       {"nodes[0]", "\"view_space\""}},
      {"cpv_first negative", [](nlohmann::json& j) { j["nodes"][1]["cpv_first"] = -1; },
       {"nodes[1]", "\"cpv_first\""}},
      {"a layer missing",
       [](nlohmann::json& j) { j["impostors"][1]["layers"].erase(j["impostors"][1]["layers"].size() - 1); },
       {"impostors[1].layers", "the plan of its box, shaft, bound and options has"}},
      {"ids without id textures",
       [](nlohmann::json& j) { j["impostors"][0]["options"]["id_textures"] = false; },
       {"impostors[0].layers[0]", "no id_textures"}},
      {"id textures without ids", [](nlohmann::json& j) { j["impostors"][1]["options"]["id_textures"] = true; },
       {"impostors[1].layers[0]", "\"ids\" is empty"}},
      {"an ids check without a file", [](nlohmann::json& j) { j["impostors"][1]["layers"][0]["ids_crc32"] = 5; },
       {"impostors[1].layers[0]", "without an ids file"}},
      {"a texture without its check", [](nlohmann::json& j) { j["impostors"][0]["layers"][0].erase("texture_crc32"); },
       {"impostors[0].layers[0]", "missing \"texture_crc32\""}},
      {"a CRC over 32 bits", [](nlohmann::json& j) { j["impostors"][0]["layers"][0]["ids_crc32"] = 1ull << 32; },
       {"impostors[0].layers[0]", "CRC-32"}},
      {"a file outside the database", [](nlohmann::json& j) { j["impostors"][0]["layers"][0]["texture"] = "../x.png"; },
       {"impostors[0].layers[0]", "\"..\""}},
      {"an absolute file", [](nlohmann::json& j) { j["impostors"][0]["layers"][0]["texture"] = "/tmp/x.png"; },
       {"impostors[0].layers[0]", "relative"}},
      {"an empty texture name", [](nlohmann::json& j) { j["impostors"][0]["layers"][0]["texture"] = ""; },
       {"impostors[0].layers[0]", "\"texture\" is empty"}},
      {"more data texels than texels",
       [](nlohmann::json& j) { j["impostors"][0]["layers"][0]["data_texels"] = 100000; },
       {"impostors[0].layers[0]", "exceeds"}},
      {"a crop outside its image",
       [](nlohmann::json& j) { j["impostors"][0]["layers"][0]["crop"] = {0, 0, 100000, 1}; },
       {"impostors[0].layers", "layer 0", "crop 100000x1"}},
      {"a crop of three numbers", [](nlohmann::json& j) { j["impostors"][0]["layers"][0]["crop"] = {0, 0, 1}; },
       {"impostors[0].layers[0]", "\"crop\" must be"}},
      {"a missing crop", [](nlohmann::json& j) { j["impostors"][0]["layers"][0].erase("crop"); },
       {"impostors[0].layers[0]", "crop"}},
      {"unknown layer member", [](nlohmann::json& j) { j["impostors"][0]["layers"][0]["mesh"] = "x"; },
       {"impostors[0].layers[0]", "unknown member \"mesh\""}},
      {"a shaft into the cluster", [](nlohmann::json& j) { j["impostors"][2]["shaft"]["min_distance"] = 0.5; },
       {"impostors[2]", "give no layered plan", "does not clear the cluster"}},
      {"a zero axis", [](nlohmann::json& j) { j["impostors"][2]["shaft"]["axis"] = {0, 0, 0}; },
       {"impostors[2]", "give no layered plan"}},
      {"a shaft without its apex", [](nlohmann::json& j) { j["impostors"][2]["shaft"].erase("apex"); },
       {"impostors[2].shaft", "missing \"apex\""}},
      {"max_texture_size 0", [](nlohmann::json& j) { j["impostors"][0]["options"]["max_texture_size"] = 0; },
       {"impostors[0].options", "\"max_texture_size\" must be an integer in 1..16384"}},
      {"an option missing", [](nlohmann::json& j) { j["impostors"][0]["options"].erase("solid_slices"); },
       {"impostors[0].options", "missing \"solid_slices\""}},
      {"an unknown option", [](nlohmann::json& j) { j["impostors"][0]["options"]["mip_maps"] = true; },
       {"impostors[0].options", "unknown member \"mip_maps\""}},
      {"a flag as a number", [](nlohmann::json& j) { j["impostors"][0]["options"]["bound_cracks"] = 0; },
       {"impostors[0].options", "\"bound_cracks\" must be true or false"}},
      {"a fractional frame width", [](nlohmann::json& j) { j["impostors"][0]["bound"]["width"] = 640.5; },
       {"impostors[0].bound", "\"width\" must be an integer"}},
      {"a bound of 0 pixels", [](nlohmann::json& j) { j["impostors"][0]["bound"]["pixels"] = 0.0; },
       {"impostors[0]", "give no layered plan"}},
      {"an empty cluster box", [](nlohmann::json& j) { j["impostors"][1]["box"]["hi"][2] = -1e9; },
       {"impostors[1].box", "is empty"}},
      {"negative capture time", [](nlohmann::json& j) { j["impostors"][1]["capture_ms"] = -0.5; },
       {"impostors[1]", "\"capture_ms\" must be >= 0"}},
  };
  for (const auto& [what, edit, parts] : cases) {
    nlohmann::json bad = good;
    bad.erase("checksum");
    edit(bad);
    writeBytes(file, placementFileText(bad));  // a valid checksum: the shape checks must find it
    std::vector<std::string> all{file};
    all.insert(all.end(), parts.begin(), parts.end());
    expectError([&] { readPlacementIndex(dir); }, all, what);
    // The writer's check (the same function) refuses it too.
    EXPECT_THROW(placementFromJson(bad, "in memory"), Error) << what;
  }
  // And the JSON damage that the checksum and the text form catch.
  writeBytes(file, good_text);
  ASSERT_NO_THROW(readPlacementIndex(dir));
  nlohmann::json stale = good;
  stale["scene"] = "edited.glb";
  writeBytes(file, stale.dump(1) + "\n");
  expectError([&] { readPlacementIndex(dir); }, {file, "checksum mismatch"}, "edited without a new checksum");
  writeBytes(file, good.dump(2) + "\n");
  expectError([&] { readPlacementIndex(dir); }, {file, "not the text the placement writer wrote"}, "reformatted");
  nlohmann::json no_checksum = good;
  no_checksum.erase("checksum");
  writeBytes(file, no_checksum.dump(1) + "\n");
  expectError([&] { readPlacementIndex(dir); }, {file, "missing \"checksum\""}, "no checksum");
  writeBytes(file, "[1, 2]\n");
  expectError([&] { readPlacementIndex(dir); }, {file, "expected an object"}, "an array");
  fs::remove(file);
  expectError([&] { readPlacementIndex(dir); }, {file, "cannot open"}, "no index");
  expectError([&] { readPlacementIndex(dir + "/absent"); }, {"absent", "not found"}, "no directory");
}

TEST(PlacementStoreIntegrityTest, TheWriterRefusesABadIndexBeforeWritingAnything) {
  const std::string dir = test::scratchDir("placement_refused").string();
  const Content c = makeContent(21);
  writeDatabase(dir, c);
  const std::string before = storedContent(dir);
  const std::string index_text = readBytes((fs::path(dir) / kPlacementIndexFile).string());
  PlacementIndex bad = readPlacementIndex(dir);
  bad.cpvs[0].impostors = {77};  // no such impostor
  ASSERT_TRUE(bad.find(77) == nullptr);
  bad.generation += 1;
  expectError([&] { writePlacementIndex(dir, bad); }, {"refused before writing", "cpvs[0].impostors[0]", "77"},
              "a cpv naming a missing impostor");
  bad = readPlacementIndex(dir);
  bad.nodes[0].children[0] = 0;
  expectError([&] { writePlacementIndex(dir, bad); }, {"refused before writing", "nodes[0].children"}, "bad children");
  bad = readPlacementIndex(dir);
  bad.impostors[0].layers[0].texture_check.known = false;  // a file not written by writePlacedImpostor
  expectError([&] { writePlacementIndex(dir, bad); }, {"impostors[0].layers[0]", "texture_crc32"}, "no check");
  EXPECT_EQ(readBytes((fs::path(dir) / kPlacementIndexFile).string()), index_text);
  EXPECT_EQ(storedContent(dir), before);
}

}  // namespace
}  // namespace farfield::store
