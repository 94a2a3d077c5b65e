// Pipeline store damage: every kind of damage to a pipeline record (ids, views, stage lists, versions, file checks,
// validity regions) gives a farfield::Error naming the element.
#include <gtest/gtest.h>

#include <cstdint>
#include <functional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "farfield/store/impostor_store.h"
#include "store/pipeline_store_fixture.h"

namespace farfield::store {
namespace {

using pipeline_store_test::expectIndexError;
using pipeline_store_test::kSceneObjects;
using pipeline_store_test::legacyJson;
using pipeline_store_test::pipelineIndex;

TEST(PipelineStoreTest, CorruptedPipelineRecordsNameTheElement) {
  const nlohmann::json good = indexToJson(pipelineIndex());
  ASSERT_NO_THROW(indexFromJson(good, "good"));
  const auto cell0 = [](nlohmann::json& j) -> nlohmann::json& { return j["cells"][0]["pipeline"]; };
  const std::string over = std::to_string(kSceneObjects + 1);

  // Object ids 0 and > scene_objects, in each id list of a record.
  struct IdList {
    std::vector<std::string> path;  // inside the cell's "pipeline"
    std::string element;            // what the message must name
  };
  const std::vector<IdList> lists{
      {{"pvs", "ids"}, "pipeline.pvs"},
      {{"split", "near"}, "pipeline.split"},
      {{"split", "far"}, "pipeline.split"},
      {{"mmi", "layers", "1", "objects"}, "layers[1]"},
      {{"single", "objects"}, "pipeline.single"},
  };
  for (const IdList& list : lists) {
    for (const uint64_t bad : {uint64_t(0), uint64_t(kSceneObjects + 1), uint64_t(1) << 40}) {
      nlohmann::json j = good;
      nlohmann::json* node = &cell0(j);
      for (const std::string& key : list.path)
        node = key == "1" ? &(*node)[size_t(1)] : &(*node)[key];
      ASSERT_TRUE(node->is_array()) << list.element;
      (*node)[0] = bad;
      SCOPED_TRACE(list.element + " id " + std::to_string(bad));
      expectIndexError(j, {"cells[0]", list.element, "outside 1.." + std::to_string(kSceneObjects)});
    }
    // Not ascending, and a repeat.
    for (const bool repeat : {false, true}) {
      nlohmann::json j = good;
      nlohmann::json* node = &cell0(j);
      for (const std::string& key : list.path)
        node = key == "1" ? &(*node)[size_t(1)] : &(*node)[key];
      ASSERT_GE(node->size(), 2u) << list.element;
      if (repeat)
        (*node)[1] = (*node)[0];
      else
        std::swap((*node)[0], (*node)[1]);
      SCOPED_TRACE(list.element + (repeat ? " repeated" : " descending"));
      expectIndexError(j, {"cells[0]", list.element, "ascending"});
    }
  }
  // A negative id and a non-number.
  {
    nlohmann::json j = good;
    cell0(j)["pvs"]["ids"][0] = -3;
    expectIndexError(j, {"pipeline.pvs", "outside"});
    j = good;
    cell0(j)["split"]["far"][0] = "5";
    expectIndexError(j, {"pipeline.split", "outside"});
  }

  // A view with triangles but no texture.
  {
    nlohmann::json j = good;
    cell0(j)["mmi"]["layers"][0]["views"][0]["texture"] = "";
    expectIndexError(j, {"cells[0]", "layers[0]", "views[0]", "no texture"});
    j = good;
    cell0(j)["single"]["views"][0]["texture"] = "";
    expectIndexError(j, {"cells[0]", "pipeline.single", "views[0]", "no texture"});
    // The empty view of the far layer (no triangles, no texture) is fine.
    j = good;
    ASSERT_EQ(cell0(j)["mmi"]["layers"][1]["views"][3]["texture"], "");
    EXPECT_NO_THROW(indexFromJson(j, "good"));
  }
  // File names escaping the store.
  for (const char* key : {"texture", "mesh"}) {
    nlohmann::json j = good;
    cell0(j)["mmi"]["layers"][1]["views"][2][key] = "cells/../../outside.bin";
    expectIndexError(j, {"layers[1]", "views[2]", key, ".."});
    j = good;
    cell0(j)["mmi"]["layers"][1]["views"][2][key] = "/etc/passwd";
    expectIndexError(j, {"layers[1]", "views[2]", key, "relative"});
  }
  // A view without a mesh file, a missing count, a bad camera.
  {
    nlohmann::json j = good;
    cell0(j)["mmi"]["layers"][0]["views"][0]["mesh"] = "";
    expectIndexError(j, {"layers[0]", "views[0]", "mesh"});
    j = good;
    cell0(j)["mmi"]["layers"][0]["views"][0].erase("triangles");
    expectIndexError(j, {"layers[0]", "views[0]", "triangles"});
    j = good;
    cell0(j)["mmi"]["layers"][0]["views"][0]["camera"]["fov_y"] = 0.0;
    expectIndexError(j, {"layers[0]", "views[0]", "camera"});
    j = good;
    cell0(j)["mmi"]["single"] = cell0(j)["single"];  // the layout of versions 2 and 3
    expectIndexError(j, {"pipeline.mmi", "single", "version 4"});
    j = good;
    cell0(j)["mmi"]["layers"] = 3;
    expectIndexError(j, {"pipeline.mmi", "layers"});
  }
  // Stage lists.
  {
    nlohmann::json j = good;
    j["online"] = {"smi"};
    expectIndexError(j, {"\"online\"", "smi", "not in the pipeline"});
    j = good;
    j["online"] = {"mmi"};
    j["pipeline"] = {"pvs", "near-far"};
    expectIndexError(j, {"\"online\"", "mmi"});
    j = good;
    j["pipeline"] = {"pvs", 3};
    expectIndexError(j, {"\"pipeline\""});
  }
  // Versions.
  {
    nlohmann::json j = good;
    j["version"] = kIndexVersion + 1;
    expectIndexError(j, {"version", std::to_string(kIndexVersion + 1)});
    j["version"] = 0;
    expectIndexError(j, {"version", "0"});
    j = legacyJson(3);
    j["version"] = 1;  // still read (with the layout of its time)
    EXPECT_NO_THROW(indexFromJson(j, "v1"));
    // Version 2 had no validity regions: read without them; version 3 requires them where a layer has views.
    j = legacyJson(3);
    cell0(j)["mmi"]["layers"][0].erase("validity");
    j["version"] = 2;
    EXPECT_NO_THROW(indexFromJson(j, "v2"));
    j["version"] = 3;
    expectIndexError(j, {"layers[0]", "validity"});
  }
  // File checks and the generation: version 3 (written with the layout of version 3: the single mesh inside mmi)
  // requires them, naming what is missing; version 2 reads without them.
  {
    const nlohmann::json good = legacyJson(3);
    using Node = std::function<nlohmann::json&(nlohmann::json&)>;
    const std::vector<std::tuple<Node, std::string, std::vector<std::string>>> needed{
        {[](nlohmann::json& j) -> nlohmann::json& { return j; }, "streets_crc32", {"top level"}},
        {[](nlohmann::json& j) -> nlohmann::json& { return j; }, "streets_bytes", {"top level"}},
        {[](nlohmann::json& j) -> nlohmann::json& { return j; }, "generation", {"top level"}},
        {[&](nlohmann::json& j) -> nlohmann::json& { return cell0(j)["mmi"]["layers"][0]["views"][0]; },
         "mesh_crc32", {"cells[0]", "layers[0]", "views[0]"}},
        {[&](nlohmann::json& j) -> nlohmann::json& { return cell0(j)["mmi"]["layers"][1]["views"][2]; },
         "texture_bytes", {"cells[0]", "layers[1]", "views[2]"}},
        {[&](nlohmann::json& j) -> nlohmann::json& { return cell0(j)["mmi"]["layers"][1]["views"][5]; },
         "ids_crc32", {"cells[0]", "layers[1]", "views[5]"}},
        {[&](nlohmann::json& j) -> nlohmann::json& { return cell0(j)["mmi"]["single"]["views"][0]; },
         "texture_crc32", {"cells[0]", "single", "views[0]"}},
    };
    for (const auto& [node, key, element] : needed) {
      SCOPED_TRACE(key);
      nlohmann::json j = good;
      ASSERT_TRUE(node(j).contains(key));
      node(j).erase(key);
      std::vector<std::string> parts = element;
      parts.push_back("missing \"" + key + "\"");
      expectIndexError(j, parts);
      // Version 2 needs no checks (but a check it has must be whole).
      j["version"] = 2;
      const std::string file_key = key.substr(0, key.rfind('_'));
      if (key != "generation") {
        ASSERT_TRUE(node(j).contains(file_key + "_crc32") || node(j).contains(file_key + "_bytes"));
        expectIndexError(j, {"missing \"" + key + "\""});
        node(j).erase(file_key + "_crc32");
        node(j).erase(file_key + "_bytes");
      }
      EXPECT_NO_THROW(indexFromJson(j, "v2"));
    }
    // A check that is not a CRC-32 or a size.
    nlohmann::json j = good;
    cell0(j)["mmi"]["layers"][0]["views"][0]["mesh_crc32"] = uint64_t(1) << 32;
    expectIndexError(j, {"views[0]", "mesh_crc32", "CRC-32"});
    cell0(j)["mmi"]["layers"][0]["views"][0]["mesh_crc32"] = -1;
    expectIndexError(j, {"views[0]", "mesh_crc32"});
    j = good;
    cell0(j)["mmi"]["layers"][0]["views"][0]["mesh_bytes"] = "12";
    expectIndexError(j, {"views[0]", "mesh_bytes"});
    // An empty view names no file and needs no check.
    j = good;
    ASSERT_FALSE(cell0(j)["mmi"]["layers"][1]["views"][3].contains("texture_crc32"));
    EXPECT_NO_THROW(indexFromJson(j, "good"));
  }
  // Version 4's own single record needs its checks too.
  {
    nlohmann::json j = good;
    cell0(j)["single"]["views"][0].erase("mesh_crc32");
    expectIndexError(j, {"cells[0]", "pipeline.single", "views[0]", "missing \"mesh_crc32\""});
  }
  // Validity regions.
  {
    nlohmann::json j = good;
    cell0(j)["mmi"]["layers"][1]["validity"][0]["envelope"] = {0.1, 0.2, 0.0, 0.1, 0.2, 0.15};
    expectIndexError(j, {"layers[1]", "validity", "decrease"});
    cell0(j)["mmi"]["layers"][1]["validity"][0]["envelope"] = {0.1, 0.2, 0.0, 0.1, 0.2};
    expectIndexError(j, {"layers[1]", "validity", "rows"});
    cell0(j)["mmi"]["layers"][1]["validity"][0]["laterals"] = 2;
    expectIndexError(j, {"layers[1]", "validity", "laterals"});
    j = good;
    cell0(j)["single"]["validity"][0]["step"] = 0.0;
    expectIndexError(j, {"pipeline.single", "validity", "step"});
    j = good;
    cell0(j)["mmi"]["layers"][0]["validity"][0]["envelope"] = {-0.1};
    expectIndexError(j, {"layers[0]", "validity", "envelope"});
    j = good;
    cell0(j)["mmi"]["layers"][0]["validity"][0].erase("origin");
    expectIndexError(j, {"layers[0]", "validity", "origin"});
    j = good;
    cell0(j)["mmi"]["layers"][1]["validity"].erase(1);  // two stations, one region
    expectIndexError(j, {"layers[1]", "validity", "station"});
    j = good;
    cell0(j)["mmi"]["layers"][1]["views"][4].erase("station");
    expectIndexError(j, {"layers[1]", "views[4]", "station"});
  }
}

}  // namespace
}  // namespace farfield::store
