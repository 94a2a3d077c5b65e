// Impostor store checksums: every file's check is the zlib CRC-32 and size of its bytes on disk, and every
// truncation and byte flip of every file, and digit flips in the index, give a farfield::Error naming the file.
#include <gtest/gtest.h>

#include <zlib.h>

#include <filesystem>
#include <functional>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/store/impostor_store.h"
#include "store/impostor_store_fixture.h"
#include "support/test_support.h"

namespace fs = std::filesystem;

namespace farfield::store {
namespace {

using impostor_store_test::expectedContent;
using impostor_store_test::filesIn;
using impostor_store_test::makeContent;
using impostor_store_test::namedFiles;
using impostor_store_test::readBytes;
using impostor_store_test::StoreContent;
using impostor_store_test::storedContent;
using impostor_store_test::writeBytes;
using impostor_store_test::writeStore;

TEST(StoreIntegrityTest, ChecksAreZlibCrc32AndSizeOfTheBytesOnDisk) {
  // The CRC-32 check value of the standard ("123456789" -> cbf43926).
  const FileCheck check = fileCheck("123456789");
  EXPECT_EQ(check.crc32, 0xcbf43926u);
  EXPECT_EQ(check.bytes, 9u);
  EXPECT_TRUE(check.known);
  const std::string dir = test::scratchDir("store_checks").string();
  const StoreContent c = makeContent(1);
  const StoreIndex written = writeStore(dir, c);
  EXPECT_EQ(storedContent(dir), expectedContent(c));
  // Every check in the index is the size and the CRC-32 (computed here with zlib directly) of its file.
  const StoreIndex index = readIndex(dir);
  size_t checked = 0;
  const auto expect_check = [&](const std::string& name, const FileCheck& check) {
    if (name.empty()) return;
    const std::string bytes = readBytes((fs::path(dir) / name).string());
    EXPECT_TRUE(check.known) << name;
    EXPECT_EQ(check.bytes, bytes.size()) << name;
    EXPECT_EQ(check.crc32, uint32_t(::crc32(0, reinterpret_cast<const Bytef*>(bytes.data()), uInt(bytes.size()))))
        << name;
    ++checked;
  };
  expect_check(index.streets, index.streets_check);
  for (const CellEntry& e : index.cells) {
    expect_check(e.texture, e.texture_check);
    for (const auto& [technique, imp] : e.impostors) expect_check(imp.mesh, imp.mesh_check);
    if (!e.pipeline) continue;
    for (const StoredView* v : {&e.pipeline->layers[0].views[0], &e.pipeline->layers[0].views[1],
                                &e.pipeline->single.views[0]}) {
      expect_check(v->texture, v->texture_check);
      expect_check(v->mesh, v->mesh_check);
      expect_check(v->ids, v->ids_check);
    }
  }
  // Every file of the store but the index is checked: streets, 1 texture and 4 meshes of the Sillion cells, 3 + 1 + 3
  // files of the views.
  EXPECT_EQ(checked, 13u);
  EXPECT_EQ(filesIn(dir).size(), checked + 1);
  EXPECT_EQ(filesIn(dir), namedFiles(index));
  // The index's own checksum covers its content.
  const nlohmann::json j = nlohmann::json::parse(readBytes((fs::path(dir) / kIndexFile).string()));
  EXPECT_EQ(j.at("checksum").get<uint32_t>(), indexChecksum(j));
  EXPECT_EQ(j.at("generation").get<uint64_t>(), 1u);
  EXPECT_EQ(written.generation, 1u);
}

TEST(StoreIntegrityTest, EveryTruncationAndByteFlipOfEveryFileIsAnErrorNamingFileAndRecord) {
  const std::string dir = test::scratchDir("store_damage").string();
  const StoreContent c = makeContent(1);
  writeStore(dir, c);
  const StoreIndex index = readIndex(dir);
  const CellEntry& a = *index.find(c.cell_a);
  const StoredView& view = a.pipeline->layers[0].views[0];
  const StoredView& single = a.pipeline->single.views[0];
  struct Target {
    std::string name;    // relative to dir
    std::string record;  // what the message must name besides the file
    std::string kind;    // to make sure each kind is covered
    std::function<void()> load;
  };
  const std::vector<Target> targets{
      {kIndexFile, "", "index", [&] { readIndex(dir); }},
      {index.streets, "streets", "streets", [&] { readIndex(dir); }},
      {a.texture, "cell 12 depth-mesh texture", "texture", [&] { loadImpostor(dir, a, "depth-mesh"); }},
      {a.impostors.at("depth-mesh").mesh, "cell 12 depth-mesh mesh", "mesh",
       [&] { loadImpostor(dir, a, "depth-mesh"); }},
      {a.impostors.at("grid-mesh").mesh, "cell 12 grid-mesh mesh", "mesh", [&] { loadImpostor(dir, a, "grid-mesh"); }},
      {view.mesh, "cell 12: mmi layer 0 view 0 mesh", "mesh", [&] { loadLayerView(dir, view); }},
      {view.texture, "cell 12: mmi layer 0 view 0 texture", "texture", [&] { loadLayerView(dir, view); }},
      {view.ids, "cell 12: mmi layer 0 view 0 ids", "ids", [&] { loadLayerView(dir, view); }},
      {a.pipeline->layers[0].views[1].mesh, "cell 12: mmi layer 0 view 1 mesh", "mesh",
       [&] { loadLayerView(dir, a.pipeline->layers[0].views[1]); }},
      {single.mesh, "cell 12: single mesh view 0 mesh", "mesh", [&] { loadLayerView(dir, single); }},
      {single.texture, "cell 12: single mesh view 0 texture", "texture", [&] { loadLayerView(dir, single); }},
      {single.ids, "cell 12: single mesh view 0 ids", "ids", [&] { loadLayerView(dir, single); }},
      {index.find(c.cell_b)->impostors.at("depth-mesh").mesh, "cell " + std::to_string(c.cell_b) + " depth-mesh mesh",
       "mesh", [&] { loadImpostor(dir, *index.find(c.cell_b), "depth-mesh"); }},
  };
  // Every kind of file, and every file the index names but the grid mesh of the empty cell (the same as depth's).
  std::set<std::string> kinds, covered;
  for (const Target& t : targets) kinds.insert(t.kind), covered.insert(t.name);
  EXPECT_EQ(kinds, (std::set<std::string>{"index", "streets", "texture", "mesh", "ids"}));
  EXPECT_EQ(covered.size() + 1, namedFiles(index).size());

  size_t cases = 0;
  for (const Target& t : targets) {
    const std::string file = (fs::path(dir) / t.name).string();
    const std::string good = readBytes(file);
    ASSERT_GT(good.size(), 2u) << t.name;
    const auto expect_damage_found = [&](const std::string& bytes, const std::string& what, const std::string& how) {
      writeBytes(file, bytes);
      try {
        t.load();
        ADD_FAILURE() << t.name << ": " << how << " not detected";
      } catch (const Error& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find(file), std::string::npos) << how << ": " << msg;
        EXPECT_NE(msg.find(t.record), std::string::npos) << how << ": " << msg;
        EXPECT_NE(msg.find(what), std::string::npos) << how << ": " << msg;
      }
      ++cases;
    };
    const bool index_file = t.kind == "index";
    const size_t n = good.size();
    for (const size_t keep : {size_t(0), size_t(1), size_t(8), n / 3, n / 2, n - 2, n - 1}) {
      const std::string what = index_file ? "" : "truncated: " + std::to_string(keep) + " of " + std::to_string(n) +
                                                     " bytes";
      expect_damage_found(good.substr(0, keep), what, "truncation to " + std::to_string(keep) + " bytes");
    }
    std::mt19937 rng{uint32_t(n)};
    std::vector<size_t> offsets{0, 1, 7, n / 2, n - 2, n - 1};
    for (int k = 0; k < 6; ++k) offsets.push_back(rng() % n);
    for (const size_t at : offsets)
      for (const uint8_t mask : {uint8_t(0x01), uint8_t(0x20), uint8_t(0x80), uint8_t(0xff)}) {
        std::string bad = good;
        bad[at] = char(uint8_t(bad[at]) ^ mask);
        expect_damage_found(bad, index_file ? "" : "checksum mismatch",
                            "flip of byte " + std::to_string(at) + " with " + std::to_string(mask));
      }
    // Trailing bytes.
    expect_damage_found(good + "x", index_file ? "" : "too long", "one byte appended");
    writeBytes(file, good);
    EXPECT_NO_THROW(t.load()) << t.name;
  }
  EXPECT_EQ(cases, targets.size() * (7 + 12 * 4 + 1));
  EXPECT_EQ(storedContent(dir), expectedContent(c));
}

TEST(StoreIntegrityTest, DigitFlipsInTheIndexAreCaughtByItsChecksum) {
  // A flip that leaves valid JSON of the same layout (a digit for another): only the checksum can see it.
  const std::string dir = test::scratchDir("store_index_digits").string();
  writeStore(dir, makeContent(1));
  const std::string file = (fs::path(dir) / kIndexFile).string();
  const std::string good = readBytes(file);
  size_t digits = 0;
  for (size_t at = 0; at < good.size(); ++at) {
    if (good[at] < '0' || good[at] > '8') continue;
    std::string bad = good;
    ++bad[at];
    writeBytes(file, bad);
    try {
      readIndex(dir);
      ADD_FAILURE() << "digit at " << at << " changed without an error";
    } catch (const Error& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(file), std::string::npos) << msg;
      // A digit of a number that does not change the text's form: the checksum says so (a digit in a name or a
      // leading zero may be refused by the shape or form checks first, which is fine too).
      EXPECT_TRUE(msg.find("checksum mismatch") != std::string::npos ||
                  msg.find("text the store writer") != std::string::npos ||
                  msg.find("not valid JSON") != std::string::npos)
          << msg;
    }
    ++digits;
  }
  EXPECT_GT(digits, 100u);
  writeBytes(file, good);
  EXPECT_NO_THROW(readIndex(dir));
}

}  // namespace
}  // namespace farfield::store
