#include "farfield/gpu/gl_counters.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <cctype>
#include <set>
#include <sstream>
#include <string>

#include "farfield/gpu/render_target.h"
#include "farfield/gpu/renderer.h"
#include "farfield/gpu/texture.h"
#include "farfield/scene/builtin.h"
#include "gpu/gpu_fixture.h"

namespace farfield::gpu {
namespace {

using test::GpuTest;

// The names of the calls gl[A-Z]...( in a source text (a word of its own, before an opening parenthesis).
std::vector<std::string> glCallsIn(const std::string& text) {
  std::vector<std::string> names;
  const auto word = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
  for (size_t i = text.find("gl"); i != std::string::npos; i = text.find("gl", i + 2)) {
    if (i > 0 && word(text[i - 1])) continue;
    if (i + 2 >= text.size() || !std::isupper(static_cast<unsigned char>(text[i + 2]))) continue;
    size_t end = i + 2;
    while (end < text.size() && word(text[end])) ++end;
    size_t open = end;
    while (open < text.size() && std::isspace(static_cast<unsigned char>(text[open]))) ++open;
    if (open < text.size() && text[open] == '(') names.push_back(text.substr(i, end - i));
  }
  return names;
}

class GlCountersTest : public GpuTest {
 protected:
  void SetUp() override {
    GpuTest::SetUp();
    if (!installGlCounters()) GTEST_SKIP() << "GL counters unavailable (FF_GL_COUNTERS=0 or no EGL context)";
  }
};

// What known calls count as: readbacks wait, draws draw, uploads send their bytes, a measurement's calls vanish.
TEST_F(GlCountersTest, ReadbacksWaitDrawsDrawAndUploadsCountTheirBytes) {
  const scene::Scene scene = scene::builtinScene("cubes");
  const GpuScene gpu_scene(scene);
  Renderer renderer;
  RenderTarget target(32, 16);
  Camera camera;
  camera.eye = Vec3(12.0f, -14.0f, 9.0f);
  camera.at = Vec3(0.0f);
  camera.width = 32, camera.height = 16;
  const std::vector<DrawItem> items = gpu_scene.drawItems();

  GlCounters before = glCounters();
  target.bind();
  target.clear(Vec4(0.0f));
  const FrameStats stats = renderer.draw(camera, items, target);
  GlCounters d = glCounters() - before;
  EXPECT_EQ(d.draw_calls, stats.draw_calls);
  EXPECT_EQ(d.syncs, 0u);
  EXPECT_GT(d.calls, d.draw_calls);
  // Per draw: its model matrix (64 bytes), normal matrix (36) and id (4) at least.
  EXPECT_GE(d.upload_bytes, 104u * stats.draw_calls);

  before = glCounters();
  target.readIds();
  target.readDepth();
  d = glCounters() - before;
  EXPECT_EQ(d.syncs, 2u);
  EXPECT_EQ(d.draw_calls, 0u);

  before = glCounters();
  image::ColorImage image(8, 4);
  Texture texture = Texture::fromImage(image);
  d = glCounters() - before;
  EXPECT_EQ(d.upload_bytes, 8u * 4u * 4u);

  before = glCounters();
  {
    GlMeasurement measurement;
    target.readColor();
    renderer.render(camera, items, target);  // its glFinish
  }
  d = glCounters() - before;
  EXPECT_EQ(d.calls, 0u);
  EXPECT_EQ(d.syncs, 0u);
  EXPECT_GT(d.measure_ms, 0.0);
  EXPECT_GT(d.driver_ms, -1e-9);
}

// Every gl* entry point called in Farfield's sources is counted: a call left out would make a frame look cheaper.
TEST(GlCounters, EveryEntryPointFarfieldCallsIsCounted) {
  const std::vector<std::string> counted = countedGlFunctions();
  const std::set<std::string> known(counted.begin(), counted.end());
  std::set<std::string> missing;
  size_t files = 0;
  for (const char* dir : {"src", "apps", "examples"}) {
    const std::filesystem::path root = std::filesystem::path(FF_SOURCE_DIR) / dir;
    if (!std::filesystem::exists(root)) continue;
    for (const auto& entry : std::filesystem::recursive_directory_iterator(root)) {
      const std::string ext = entry.path().extension().string();
      if (ext != ".cpp" && ext != ".h") continue;
      std::ifstream in(entry.path());
      std::stringstream text;
      text << in.rdbuf();
      const std::string s = text.str();
      ++files;
      for (const std::string& name : glCallsIn(s)) {
        // glTF, glm, the counters' and the barrier check's own functions are not GL entry points.
        if (name == "glTF" || name.rfind("glm", 0) == 0 || name.rfind("glCounters", 0) == 0 ||
            name.rfind("glBarrier", 0) == 0)
          continue;
        if (!known.count(name)) missing.insert(name + " (" + entry.path().filename().string() + ")");
      }
    }
  }
  EXPECT_GT(files, 100u);
  for (const std::string& name : missing) ADD_FAILURE() << "not counted: " << name;
}

}  // namespace
}  // namespace farfield::gpu
