// Parsing the extractor pipeline's stages (--pipeline) and the tail left online (--online), and the techniques that
// name the single stage with its mesh.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "farfield/bake/pipeline.h"
#include "farfield/core/error.h"
#include "support/expect_error.h"

namespace farfield::bake {
using namespace farfield::extract;
namespace {

using test::expectErrorMentions;

// Expects parsePipeline to throw a farfield::Error whose message contains `what` (the option it names).
void expectParseError(const std::string& stages, const std::string& online, const std::string& what) {
  try {
    parsePipeline(stages, online);
    ADD_FAILURE() << "expected farfield::Error for --pipeline '" << stages << "' --online '" << online << "'";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(what), std::string::npos)
        << "--pipeline '" << stages << "' --online '" << online << "': " << e.what();
  }
}

TEST(PipelineParseTest, AcceptsTheValidPipelinesAndSplits) {
  using V = std::vector<std::string>;
  PipelineSpec s = parsePipeline("pvs,near-far,mmi");
  EXPECT_EQ(s.stages, (V{"pvs", "near-far", "mmi"}));
  EXPECT_EQ(s.online_from, 3u);
  EXPECT_EQ(s.baked(), (V{"pvs", "near-far", "mmi"}));
  EXPECT_TRUE(s.online().empty());

  s = parsePipeline("near-far,mmi");
  EXPECT_EQ(s.stages, (V{"near-far", "mmi"}));
  EXPECT_EQ(s.online_from, 2u);

  s = parsePipeline("pvs,near-far");
  EXPECT_EQ(s.stages, (V{"pvs", "near-far"}));
  EXPECT_TRUE(s.online().empty());

  s = parsePipeline("pvs", "");
  EXPECT_EQ(s.stages, (V{"pvs"}));

  s = parsePipeline("pvs,near-far,mmi", "mmi");
  EXPECT_EQ(s.online_from, 2u);
  EXPECT_EQ(s.baked(), (V{"pvs", "near-far"}));
  EXPECT_EQ(s.online(), (V{"mmi"}));

  s = parsePipeline("pvs,near-far,mmi", "near-far,mmi");
  EXPECT_EQ(s.online_from, 1u);
  EXPECT_EQ(s.baked(), (V{"pvs"}));
  EXPECT_EQ(s.online(), (V{"near-far", "mmi"}));

  s = parsePipeline("near-far,mmi", "mmi");
  EXPECT_EQ(s.baked(), (V{"near-far"}));
  EXPECT_EQ(s.online(), (V{"mmi"}));

  // Everything online but the PVS-less pipeline's first stage is allowed too.
  s = parsePipeline("near-far,mmi", "near-far,mmi");
  EXPECT_TRUE(s.baked().empty());
  EXPECT_EQ(s.online(), (V{"near-far", "mmi"}));

  // The single stage: after near-far, before mmi; alone (Sillion's cell impostor) or with mmi, online like mmi.
  s = parsePipeline("near-far,single");
  EXPECT_EQ(s.stages, (V{"near-far", "single"}));
  s = parsePipeline("pvs,near-far,single");
  EXPECT_EQ(s.stages, (V{"pvs", "near-far", "single"}));
  s = parsePipeline("pvs,near-far,single,mmi");
  EXPECT_EQ(s.stages, (V{"pvs", "near-far", "single", "mmi"}));
  s = parsePipeline(kTechniquePipeline);
  EXPECT_EQ(s.stages, (V{"near-far", "single"}));
  s = parsePipeline("pvs,near-far,single,mmi", "mmi");
  EXPECT_EQ(s.baked(), (V{"pvs", "near-far", "single"}));
  s = parsePipeline("pvs,near-far,single,mmi", "single,mmi");
  EXPECT_EQ(s.online(), (V{"single", "mmi"}));
  s = parsePipeline("near-far,single", "single");
  EXPECT_EQ(s.baked(), (V{"near-far"}));
  EXPECT_EQ(s.online(), (V{"single"}));
}

TEST(PipelineParseTest, RejectsBadPipelinesAndSplits) {
  expectParseError("", "", "--pipeline");
  expectParseError("pvs,near-far,smi", "", "--pipeline");         // unknown stage
  expectParseError("pvs,near-far,smi", "", "smi");
  expectParseError("pvs,,mmi", "", "--pipeline");                  // empty stage name
  expectParseError("pvs,near-far,", "", "--pipeline");             // trailing comma
  expectParseError("PVS,near-far", "", "--pipeline");              // names are case-sensitive
  expectParseError("pvs,near-far,near-far,mmi", "", "--pipeline");  // repeated
  expectParseError("pvs,pvs", "", "twice");
  expectParseError("near-far,pvs,mmi", "", "--pipeline");          // wrong order
  expectParseError("pvs,mmi,near-far", "", "--pipeline");
  expectParseError("mmi", "", "--pipeline");                        // mmi without near-far
  expectParseError("pvs,mmi", "", "near-far");
  // Online stages.
  expectParseError("pvs,near-far,mmi", "near-far", "--online");      // not the tail
  expectParseError("pvs,near-far,mmi", "mmi,near-far", "--online");  // the tail, but out of order
  expectParseError("pvs,near-far,mmi", "mmi,mmi", "--online");
  expectParseError("pvs,near-far,mmi", "pvs", "--online");            // pvs online
  expectParseError("pvs,near-far,mmi", "pvs,near-far,mmi", "--online");
  expectParseError("pvs,near-far", "mmi", "--online");                // not in the pipeline
  expectParseError("pvs,near-far", "mmi", "not in the pipeline");
  expectParseError("pvs,near-far,mmi", "smi", "--online");
  expectParseError("pvs,near-far,mmi", "mmi,", "--online");
  // The single stage: one order (pvs, near-far, single, mmi), near-far before it, online only as part of the tail.
  expectParseError("pvs,near-far,mmi,single", "", "the order is pvs, near-far, single, mmi");
  expectParseError("pvs,near-far,mmi,single", "", "'single' must come before 'mmi'");
  expectParseError("single,near-far", "", "--pipeline");
  expectParseError("single", "", "single needs near-far");
  expectParseError("pvs,single", "", "single needs near-far");
  expectParseError("near-far,single,single", "", "twice");
  expectParseError("pvs,near-far,single,mmi", "single", "--online");  // not the tail
  expectParseError("pvs,near-far,single,mmi", "mmi,single", "--online");
  expectParseError("near-far,mmi", "single", "not in the pipeline");
}

TEST(PipelineParseTest, TechniquesAreTheSingleStageWithTheirMesh) {
  EXPECT_EQ(techniqueMesh("depth-mesh"), LayerMesh::DepthMesh);
  EXPECT_EQ(techniqueMesh("grid-mesh"), LayerMesh::Grid);
  // "both" made one store of two meshes from one capture; a store now holds one mesh kind.
  expectErrorMentions([] { techniqueMesh("both"); }, {"--technique", "both", "twice"});
  expectErrorMentions([] { techniqueMesh("depth"); }, {"--technique", "depth"});
  expectErrorMentions([] { techniqueMesh("grid", "mode 'x'"); }, {"mode 'x'", "grid"});
}

}  // namespace
}  // namespace farfield::bake
