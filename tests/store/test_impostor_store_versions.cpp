// Impostor store versions: version 1 and 2 stores are read without checksums and rewritten as the current version;
// a version 3 index missing a check is an error naming what is missing, and the writer refuses one.
#include <gtest/gtest.h>

#include <filesystem>
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
using impostor_store_test::expectError;
using impostor_store_test::filesIn;
using impostor_store_test::makeContent;
using impostor_store_test::namedFiles;
using impostor_store_test::readBytes;
using impostor_store_test::StoreContent;
using impostor_store_test::storedContent;
using impostor_store_test::writeBytes;
using impostor_store_test::writeStore;

TEST(StoreIntegrityTest, Version2StoresAreReadWithoutChecksumsAndRewrittenAsTheCurrentVersion) {
  const std::string dir = test::scratchDir("store_v2").string();
  const StoreContent old_content = makeContent(1);
  const StoreIndex v2 = writeStore(dir, old_content, 2);
  // The files and index of the version 2 format: old names, no checks, no generation, no checksum.
  const std::string text = readBytes((fs::path(dir) / kIndexFile).string());
  for (const char* absent : {"checksum", "_crc32", "_bytes", "generation", "g000"})
    EXPECT_EQ(text.find(absent), std::string::npos) << absent;
  EXPECT_TRUE(fs::is_regular_file(fs::path(dir) / "streets.json"));
  EXPECT_TRUE(fs::is_regular_file(fs::path(dir) / "cells/e000012.png"));
  EXPECT_TRUE(fs::is_regular_file(fs::path(dir) / "cells/e000012.mmi.00.0.ids.png"));
  const StoreIndex index = readIndex(dir);
  EXPECT_EQ(index.version, 2);
  EXPECT_FALSE(index.streets_check.known);
  EXPECT_FALSE(index.find(12)->texture_check.known);
  EXPECT_FALSE(index.find(12)->pipeline->layers[0].views[0].mesh_check.known);
  EXPECT_EQ(storedContent(dir), expectedContent(old_content));
  // The version 2 layout (no single stage; the single mesh inside mmi, built by it: options.pipeline.single_mesh) is
  // read as the single stage's record.
  const nlohmann::json v2_json = nlohmann::json::parse(text);
  EXPECT_EQ(v2_json.at("pipeline"), nlohmann::json({"pvs", "near-far", "mmi"}));
  EXPECT_TRUE(v2_json.at("cells")[0].at("pipeline").at("mmi").contains("single"));
  EXPECT_FALSE(v2_json.at("cells")[0].at("pipeline").contains("single"));
  EXPECT_EQ(index.pipeline, (std::vector<std::string>{"pvs", "near-far", "single", "mmi"}));
  EXPECT_TRUE(index.find(12)->pipeline->has_single);
  EXPECT_EQ(index.find(12)->pipeline->single.views.size(), 1u);
  // A version 1 index is read too (the Sillion part).
  nlohmann::json j = nlohmann::json::parse(text);
  j["version"] = 1;
  for (nlohmann::json& cell : j["cells"]) cell.erase("pipeline");
  j.erase("pipeline");
  writeBytes((fs::path(dir) / kIndexFile).string(), j.dump(1) + "\n");
  EXPECT_EQ(readIndex(dir).version, 1);
  writeBytes((fs::path(dir) / kIndexFile).string(), text);

  // A bake over it writes generation 1 of a store of the current version and removes the version 2 files; unrelated
  // files stay.
  writeBytes((fs::path(dir) / "notes.txt").string(), "mine");
  writeBytes((fs::path(dir) / "cells" / "README").string(), "mine too");
  const StoreContent new_content = makeContent(2);
  const StoreIndex v3 = writeStore(dir, new_content);
  EXPECT_EQ(v3.generation, 1u);
  EXPECT_EQ(storedContent(dir), expectedContent(new_content));
  std::set<std::string> expected = namedFiles(v3);
  expected.insert("notes.txt");
  expected.insert("cells/README");
  EXPECT_EQ(filesIn(dir), expected);
  (void)v2;
}

TEST(StoreIntegrityTest, Version3IndexWithoutChecksumsIsAnErrorNamingWhatIsMissing) {
  const std::string dir = test::scratchDir("store_v3_missing").string();
  writeStore(dir, makeContent(1), 3);  // the layout of version 3 (the single mesh inside mmi), relabelled 2 below
  const std::string file = (fs::path(dir) / kIndexFile).string();
  const nlohmann::json good = nlohmann::json::parse(readBytes(file));
  const auto expect_missing = [&](nlohmann::json j, const std::vector<std::string>& parts) {
    writeBytes(file, indexFileText(j));
    try {
      readIndex(dir);
      ADD_FAILURE() << "expected an error naming " << parts.back();
    } catch (const Error& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(file), std::string::npos) << msg;
      for (const std::string& part : parts) EXPECT_NE(msg.find(part), std::string::npos) << part << " in " << msg;
    }
  };
  nlohmann::json j = good;
  j.erase("streets_crc32");
  expect_missing(j, {"top level", "missing \"streets_crc32\""});
  j = good;
  j["cells"][0].erase("texture_bytes");
  expect_missing(j, {"cells[0]", "missing \"texture_bytes\""});
  j = good;
  j["cells"][1]["impostors"]["grid-mesh"].erase("mesh_crc32");
  expect_missing(j, {"cells[1]: impostors.grid-mesh", "missing \"mesh_crc32\""});
  j = good;
  j["cells"][0]["pipeline"]["mmi"]["layers"][0]["views"][0].erase("ids_crc32");
  expect_missing(j, {"cells[0]: pipeline.mmi.layers[0]: views[0]", "missing \"ids_crc32\""});
  j = good;
  j["cells"][0]["pipeline"]["mmi"]["single"]["views"][0].erase("mesh_bytes");
  expect_missing(j, {"cells[0]: pipeline.mmi.single: views[0]", "missing \"mesh_bytes\""});
  // A whole check gone (as in a version 2 index relabelled 3), and the generation.
  j = good;
  j["cells"][0]["pipeline"]["mmi"]["layers"][0]["views"][0].erase("texture_crc32");
  j["cells"][0]["pipeline"]["mmi"]["layers"][0]["views"][0].erase("texture_bytes");
  expect_missing(j, {"cells[0]: pipeline.mmi.layers[0]: views[0]", "missing \"texture_crc32\""});
  j = good;
  j.erase("streets_crc32");
  j.erase("streets_bytes");
  expect_missing(j, {"top level", "missing \"streets_crc32\""});
  j = good;
  j["cells"][0]["impostors"]["depth-mesh"].erase("mesh_crc32");
  j["cells"][0]["impostors"]["depth-mesh"].erase("mesh_bytes");
  expect_missing(j, {"cells[0]: impostors.depth-mesh", "missing \"mesh_crc32\""});
  j = good;
  j.erase("generation");
  expect_missing(j, {"top level", "missing \"generation\""});
  // The same index labelled version 2 (which has no index checksum either) is read without them.
  j["version"] = 2;
  j.erase("checksum");
  j["cells"][0]["impostors"]["depth-mesh"].erase("mesh_crc32");
  j["cells"][0]["impostors"]["depth-mesh"].erase("mesh_bytes");
  writeBytes(file, indexFileText(j));
  EXPECT_NO_THROW(readIndex(dir));
  // The index's own checksum.
  writeBytes(file, good.dump(1) + "\n");
  EXPECT_NO_THROW(readIndex(dir));
  j = good;
  j.erase("checksum");
  writeBytes(file, j.dump(1) + "\n");
  expectError([&] { readIndex(dir); }, file, "top level: missing \"checksum\"");
  writeBytes(file, good.dump(1) + "\n");

  // The writer refuses a version 3 index with a file it has no check for, naming the record.
  StoreIndex index = readIndex(dir);
  index.cells[0].pipeline->layers[0].views[0].texture_check = {};
  expectError([&] { writeIndex(dir, index); }, file, "cell 12: mmi layer 0 view 0 texture: no size and CRC-32");
  index = readIndex(dir);
  index.streets_check = {};
  expectError([&] { writeIndex(dir, index); }, file, "streets: no size and CRC-32");
  EXPECT_NO_THROW(readIndex(dir));  // the refused writes changed nothing
}

}  // namespace
}  // namespace farfield::store
