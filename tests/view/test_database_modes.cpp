// The modes a database offers the viewer, from its index, by the rules runtime::Walkthrough checks: every
// representation offered can be opened (and those not offered cannot), and bad databases are errors naming the file.
#include "farfield/view/database_modes.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "farfield/core/error.h"
#include "farfield/gpu/renderer.h"
#include "farfield/runtime/walkthrough.h"
#include "farfield/view/mode_renderer.h"
#include "view/view_test_city.h"

namespace fs = std::filesystem;

namespace farfield::view {
namespace {

std::string errorOf(const std::string& dir) {
  try {
    databaseModes(dir);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(DatabaseModes, NoDatabaseOffersFullAndCulled) {
  const DatabaseModes m = databaseModes("");
  EXPECT_EQ(m.kind, DatabaseKind::None);
  EXPECT_EQ(m.modes, (std::vector<std::string>{"full", "culled"}));
  EXPECT_EQ(defaultMode(m), "full");
}

TEST(DatabaseModes, APipelineStoreOffersWhatTheWalkthroughCanOpen) {
  const test::ViewCity& c = test::viewCity();
  const DatabaseModes m = databaseModes(c.store);
  EXPECT_EQ(m.kind, DatabaseKind::Pipeline);
  EXPECT_EQ(m.modes, (std::vector<std::string>{"full", "culled", "local", "visible", "smi", "mmi-dynamic", "mmi"}));
  EXPECT_EQ(defaultMode(m), "mmi");
  EXPECT_TRUE(fs::exists(m.streets_file));
  // Each offered representation opens; placed (not offered) does not.
  gpu::sharedHeadlessContext();
  const gpu::GpuScene gpu_scene(c.city.scene);
  const scene::Bvh bvh(c.city.scene);
  gpu::Renderer renderer;
  for (const std::string& mode : m.modes) {
    const auto representation = runtime::representationFromName(mode);
    if (!representation || *representation == runtime::Representation::MmiDynamic) continue;  // calibration: slow
    runtime::WalkthroughOptions options;
    options.database = c.store;
    options.representation = *representation;
    EXPECT_NO_THROW(runtime::Walkthrough(c.city.scene, gpu_scene, bvh, renderer, options)) << mode;
  }
  runtime::WalkthroughOptions placed;
  placed.database = c.store;
  placed.representation = runtime::Representation::Placed;
  EXPECT_THROW(runtime::Walkthrough(c.city.scene, gpu_scene, bvh, renderer, placed), Error);
}

TEST(DatabaseModes, BadDatabasesAreErrorsNamingTheFile) {
  const fs::path dir = farfield::test::scratchDir("database_modes");
  EXPECT_NE(errorOf((dir / "nothing.imp").string()).find("nothing.imp"), std::string::npos);
  fs::create_directories(dir / "empty.imp");
  EXPECT_NE(errorOf((dir / "empty.imp").string()).find("holds neither index.json"), std::string::npos);
  fs::create_directories(dir / "garbled.imp");
  std::ofstream(dir / "garbled.imp" / "index.json") << "{\"format\": ";
  EXPECT_NE(errorOf((dir / "garbled.imp").string()).find("index.json"), std::string::npos);
  // Every truncation of a real index is an error naming it.
  const test::ViewCity& c = test::viewCity();
  const fs::path copy = dir / "cut.imp";
  fs::copy(c.store, copy, fs::copy_options::recursive);
  const uintmax_t size = fs::file_size(copy / "index.json");
  for (uintmax_t keep : {uintmax_t(0), uintmax_t(1), size / 3, size - 2}) {
    fs::copy_file(fs::path(c.store) / "index.json", copy / "index.json", fs::copy_options::overwrite_existing);
    fs::resize_file(copy / "index.json", keep);
    EXPECT_NE(errorOf(copy.string()).find("index.json"), std::string::npos) << keep << " bytes";
  }
}

}  // namespace
}  // namespace farfield::view
