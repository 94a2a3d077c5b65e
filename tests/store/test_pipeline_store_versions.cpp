// Pipeline store versions 2 and 3: the single mesh held inside the mmi record is read as version 4's single stage,
// and a version 2 or 3 index with a single stage, or without the single_mesh option, is refused naming the part.
#include <gtest/gtest.h>

#include <cstddef>
#include <string>
#include <vector>

#include "farfield/store/impostor_store.h"
#include "store/pipeline_store_fixture.h"

namespace farfield::store {
namespace {

using pipeline_store_test::expectIndexError;
using pipeline_store_test::legacyIndex;
using pipeline_store_test::legacyJson;
using pipeline_store_test::onlineCell;

TEST(PipelineStoreTest, Version2And3SingleMeshInsideMmiIsReadAsTheSingleStage) {
  for (const int version : {2, 3}) {
    SCOPED_TRACE("version " + std::to_string(version));
    const StoreIndex legacy = legacyIndex(version);
    const nlohmann::json j = legacyJson(version);
    // Written with that version's layout.
    EXPECT_EQ(j["pipeline"], nlohmann::json({"pvs", "near-far", "mmi"}));
    ASSERT_TRUE(j["cells"][0]["pipeline"]["mmi"].contains("single"));
    EXPECT_FALSE(j["cells"][0]["pipeline"].contains("single"));
    // Read as version 4 holds it: the stage list has single, each mmi record's single mesh is the single stage's.
    const StoreIndex read = indexFromJson(j, "old");
    EXPECT_EQ(read.version, version);
    EXPECT_EQ(read.pipeline, (std::vector<std::string>{"pvs", "near-far", "single", "mmi"}));
    for (size_t k = 0; k < 2; ++k) {
      const CellPipeline& p = *read.cells[k].pipeline;
      EXPECT_TRUE(p.has_single);
      ASSERT_EQ(p.single.views.size(), 1u);
      EXPECT_EQ(p.single.objects, legacy.cells[k].pipeline->single.objects);
      EXPECT_EQ(p.single.views[0].mesh, legacy.cells[k].pipeline->single.views[0].mesh);
    }
    EXPECT_FALSE(read.cells[2].pipeline->has_single);  // the cell without mmi record has none
    // mmi online: the single mesh was built online by it, so single is online too.
    StoreIndex online = legacyIndex(version);
    online.online = {"mmi"};
    online.cells = {onlineCell(3)};
    const StoreIndex online_read = indexFromJson(indexToJson(online), "old online");
    EXPECT_EQ(online_read.pipeline, (std::vector<std::string>{"pvs", "near-far", "single", "mmi"}));
    EXPECT_EQ(online_read.online, (std::vector<std::string>{"single", "mmi"}));
    // single_mesh false: the mmi stage built no single mesh; no single stage.
    nlohmann::json no_single = j;
    no_single["options"]["pipeline"]["single_mesh"] = false;
    const StoreIndex without = indexFromJson(no_single, "old");
    EXPECT_EQ(without.pipeline, (std::vector<std::string>{"pvs", "near-far", "mmi"}));
    EXPECT_FALSE(without.cells[0].pipeline->has_single);
    EXPECT_TRUE(without.cells[0].pipeline->single.views.empty());
    // single_mesh is required there, a boolean: not silently taken as either.
    nlohmann::json bad = j;
    bad["options"]["pipeline"].erase("single_mesh");
    expectIndexError(bad, {"options", "pipeline", "single_mesh"});
    bad["options"]["pipeline"]["single_mesh"] = 1;
    expectIndexError(bad, {"options", "pipeline", "single_mesh"});
    bad.erase("options");
    expectIndexError(bad, {"options", "pipeline", "single_mesh"});
    // Versions 2 and 3 had no single stage.
    bad = j;
    bad["pipeline"] = {"pvs", "near-far", "single", "mmi"};
    expectIndexError(bad, {"\"pipeline\"", "single", "version " + std::to_string(version)});
    bad = j;
    bad["cells"][0]["pipeline"]["single"] = bad["cells"][0]["pipeline"]["mmi"]["single"];
    expectIndexError(bad, {"cells[0]", "single", "no single stage"});
    // The mmi record must still hold the single mesh.
    bad = j;
    bad["cells"][0]["pipeline"]["mmi"].erase("single");
    expectIndexError(bad, {"pipeline.mmi", "single"});
  }
}

}  // namespace
}  // namespace farfield::store
