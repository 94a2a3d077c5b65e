// The viewer run as a script (--replay, --screenshot-at, --exit) in a real window under Xvfb: its frames equal an
// independent render of the same camera and mode (full: the renderer drawing all of the scene's items; mmi: eval's
// FrameRunner running the bench's mmi mode over the same path), its window screenshot shows panels over the frame,
// a recorded path replays to the same cameras, and a bad database is an error naming the file, not a crash.
#include "farfield/view/viewer.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>

#include "farfield/core/error.h"
#include "farfield/eval/frame_runner.h"
#include "farfield/eval/impostor_mode.h"
#include "farfield/eval/mode.h"
#include "farfield/image/metrics.h"
#include "farfield/image/png_io.h"
#include "farfield/store/placement_store.h"
#include "farfield/view/database_modes.h"
#include "view/view_test_city.h"

namespace fs = std::filesystem;

namespace farfield::view {
namespace {

constexpr int kWidth = 320, kHeight = 180;

ViewerOptions scripted(const std::string& out_dir, const std::string& mode) {
  const test::ViewCity& c = test::viewCity();
  ViewerOptions o;
  o.replay = c.path_file;
  o.screenshot_at = {0, 3, 7};
  o.out_dir = out_dir;
  o.exit_at_end = true;
  o.width = kWidth;
  o.height = kHeight;
  o.mode = mode;
  return o;
}

std::string errorOf(const scene::Scene& scene, const ViewerOptions& options) {
  try {
    runViewer(scene, options);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(Viewer, ReplayedFullFramesEqualTheRendererAtTheSameCamera) {
  FF_REQUIRE_DISPLAY();
  const test::ViewCity& c = test::viewCity();
  const std::string out = farfield::test::scratchDir("view_full").string();
  runViewer(c.city.scene, scripted(out, "full"));

  gpu::sharedHeadlessContext();
  const gpu::GpuScene gpu_scene(c.city.scene);
  gpu::Renderer renderer;
  gpu::RenderTarget target(kWidth, kHeight);
  const std::vector<gpu::DrawItem> items = gpu_scene.drawItems();
  for (size_t i : {0, 3, 7}) {
    renderer.render(eval::pathCamera(c.path, i, kWidth, kHeight), items, target);
    const image::ColorImage frame = image::readPng(out + "/frame_" + std::to_string(i) + ".png");
    EXPECT_GT(image::psnr(frame, target.readColor()), 40.0) << "frame " << i;
    // The window shows the frame under the panels: same size, not the same pixels.
    const image::ColorImage window = image::readPng(out + "/window_" + std::to_string(i) + ".png");
    ASSERT_EQ(window.width(), kWidth);
    ASSERT_EQ(window.height(), kHeight);
    EXPECT_LT(image::psnr(window, frame), 30.0) << "no panels in window_" << i << ".png";
  }
  // A frame of another camera is not close: the comparison can fail.
  renderer.render(eval::pathCamera(c.path, 7, kWidth, kHeight), items, target);
  EXPECT_LT(image::psnr(image::readPng(out + "/frame_0.png"), target.readColor()), 40.0);
}

TEST(Viewer, ReplayedImpostorFramesEqualTheBenchModeAtTheSameCamera) {
  FF_REQUIRE_DISPLAY();
  const test::ViewCity& c = test::viewCity();
  for (const std::string mode : {"mmi", "smi", "culled"}) {
    const std::string out = farfield::test::scratchDir("view_" + mode).string();
    ViewerOptions options = scripted(out, mode);
    options.impostors = c.store;
    options.error_px = 1000.0;  // every layer an impostor: frames that differ from full geometry
    runViewer(c.city.scene, options);

    gpu::sharedHeadlessContext();
    eval::registerImpostorModes();
    std::map<std::string, std::string> mode_options{{"impostor_dir", c.store}};
    if (mode != "culled") mode_options["error_px"] = "1000";
    eval::ModeRunResources run(c.city.scene, kWidth, kHeight, mode_options);
    gpu::RenderTarget full_target(kWidth, kHeight);
    size_t unlike_full = 0;
    std::unique_ptr<eval::Mode> bench_mode = eval::createMode(mode, run.context);
    bench_mode->prepare(run.context);
    eval::FrameRunner runner(run.renderer, run.target);
    for (size_t i = 0; i < c.path.frames.size(); ++i) {
      runner.run(*bench_mode, eval::pathCamera(c.path, i, kWidth, kHeight), i);
      if (i != 0 && i != 3 && i != 7) continue;
      const image::ColorImage frame = image::readPng(out + "/frame_" + std::to_string(i) + ".png");
      EXPECT_GT(image::psnr(frame, run.target.readColor()), 40.0) << mode << " frame " << i;
      run.renderer.render(eval::pathCamera(c.path, i, kWidth, kHeight), run.gpu_scene.drawItems(), full_target);
      if (image::psnr(frame, full_target.readColor()) < 60.0) ++unlike_full;
    }
    // The impostor modes draw impostors (not the geometry) in some frame; culled draws exactly what full does.
    if (mode == "culled")
      EXPECT_EQ(unlike_full, 0u);
    else
      EXPECT_GT(unlike_full, 0u) << mode;
  }
}

constexpr int kPlacementSize = 128;  // the frames the test placement was made for

// The viewer over the test placement, replaying its path in `mode` and writing frames 0, 3 and 7 to out_dir.
ViewerOptions placementScript(const std::string& out_dir, const std::string& mode) {
  const test::ViewPlacement& c = test::viewPlacement();
  ViewerOptions o = scripted(out_dir, mode);
  o.replay = c.path_file;
  o.width = o.height = kPlacementSize;
  o.impostors = c.database;
  return o;
}

TEST(Viewer, ReplayedPlacedFramesEqualTheBenchModeAtTheSameCamera) {
  FF_REQUIRE_DISPLAY();
  const test::ViewPlacement& c = test::viewPlacement();
  ASSERT_GT(c.report.impostors, 0u) << "the placement placed nothing: the test would not see an impostor";
  const int size = kPlacementSize;
  const std::string out = farfield::test::scratchDir("view_placed").string();
  runViewer(c.city.scene, placementScript(out, "placed"));

  gpu::sharedHeadlessContext();
  eval::registerImpostorModes();
  eval::ModeRunResources run(c.city.scene, size, size, {{"impostor_dir", c.database}});
  std::unique_ptr<eval::Mode> bench_mode = eval::createMode("placed", run.context);
  bench_mode->prepare(run.context);
  eval::FrameRunner runner(run.renderer, run.target);
  for (size_t i = 0; i < c.path.frames.size(); ++i) {
    runner.run(*bench_mode, eval::pathCamera(c.path, i, size, size), i);
    if (i != 0 && i != 3 && i != 7) continue;
    const image::ColorImage frame = image::readPng(out + "/frame_" + std::to_string(i) + ".png");
    EXPECT_GT(image::psnr(frame, run.target.readColor()), 40.0) << "placed frame " << i;
  }
  // The path meets the placement's impostors (the frames compared are not geometry only).
  EXPECT_GT(bench_mode->info().at("impostor_draws"), 0.0);
  // Another frame of the path is not close: the comparison can fail.
  runner.run(*bench_mode, eval::pathCamera(c.path, 7, size, size), 7);
  EXPECT_LT(image::psnr(image::readPng(out + "/frame_0.png"), run.target.readColor()), 40.0);
}

// Over a placement the viewer offers placed and governed (placed under the frame governor), opens on placed, and its
// governed frames are the bench's governed mode's under the same budget: here one no level meets, so that every
// frame is drawn at the coarsest level (half the resolution, 4 px geometry) and says the bound it kept.
TEST(Viewer, ReplayedGovernedFramesEqualTheBenchModeUnderTheSameBudget) {
  FF_REQUIRE_DISPLAY();
  const test::ViewPlacement& c = test::viewPlacement();
  const DatabaseModes modes = databaseModes(c.database);
  EXPECT_EQ(modes.modes, (std::vector<std::string>{"full", "culled", "placed", "governed"}));
  EXPECT_EQ(defaultMode(modes), "placed");
  const int size = kPlacementSize;
  const std::string out = farfield::test::scratchDir("view_governed").string();
  ViewerOptions options = placementScript(out, "governed");
  options.t_max_ms = 0.001;
  runViewer(c.city.scene, options);

  gpu::sharedHeadlessContext();
  eval::registerImpostorModes();
  char number[32];
  std::snprintf(number, sizeof(number), "%.17g",
                store::readPlacementIndex(c.database).options.at("error_px").get<double>());
  eval::ModeRunResources run(c.city.scene, size, size,
                             {{"impostor_dir", c.database}, {"governed", "placed"}, {"governor_t_max_ms", "0.001"},
                              {"governor_error_px", number}});
  std::unique_ptr<eval::Mode> governed = eval::createMode("governed", run.context);
  governed->prepare(run.context);
  eval::FrameRunner runner(run.renderer, run.target);
  for (size_t i = 0; i < c.path.frames.size(); ++i) {
    const eval::FrameRecord record = runner.run(*governed, eval::pathCamera(c.path, i, size, size), i);
    EXPECT_GT(record.bound_scale, 1.0) << "frame " << i << ": not relaxed under a budget no level meets";
    if (i != 0 && i != 3 && i != 7) continue;
    const image::ColorImage frame = image::readPng(out + "/frame_" + std::to_string(i) + ".png");
    EXPECT_GT(image::psnr(frame, run.target.readColor()), 40.0) << "governed frame " << i;
  }
  // The placed walkthrough's own frame (level 0, the full resolution) is not close: the comparison can fail.
  std::unique_ptr<eval::Mode> placed = eval::createMode("placed", run.context);
  placed->prepare(run.context);
  runner.run(*placed, eval::pathCamera(c.path, 3, size, size), 3);
  EXPECT_LT(image::psnr(image::readPng(out + "/frame_3.png"), run.target.readColor()), 40.0);
}

TEST(Viewer, TintShowsImpostorsInTheirKindsColour) {
  FF_REQUIRE_DISPLAY();
  const test::ViewCity& c = test::viewCity();
  const std::string plain = farfield::test::scratchDir("view_plain").string();
  const std::string tinted = farfield::test::scratchDir("view_tinted").string();
  ViewerOptions options = scripted(plain, "mmi");
  options.impostors = c.store;
  options.error_px = 1000.0;  // every layer an impostor
  runViewer(c.city.scene, options);
  options.out_dir = tinted;
  options.tint = true;
  runViewer(c.city.scene, options);
  size_t tinted_frames = 0;
  for (int i : {0, 3, 7}) {
    const std::string name = "/frame_" + std::to_string(i) + ".png";
    const image::ColorImage a = image::readPng(plain + name), b = image::readPng(tinted + name);
    if (image::psnr(a, b) < 40.0) ++tinted_frames;  // tinted impostors change the frame
    // Geometry is untouched: many pixels are equal.
    size_t equal = 0;
    for (size_t p = 0; p < a.pixelCount(); ++p) equal += a.pixels()[p] == b.pixels()[p] ? 1 : 0;
    EXPECT_GT(equal, a.pixelCount() / 2) << "frame " << i;
  }
  EXPECT_GT(tinted_frames, 0u);
}

TEST(Viewer, ARecordedPathReplaysToTheSameCameras) {
  FF_REQUIRE_DISPLAY();
  const test::ViewCity& c = test::viewCity();
  const std::string out = farfield::test::scratchDir("view_record").string();
  ViewerOptions options = scripted(out, "culled");
  options.screenshot_at.clear();
  options.screenshot_at = {7};
  options.record = out + "/first.json";
  runViewer(c.city.scene, options);
  options.replay = options.record;
  options.record = out + "/second.json";
  runViewer(c.city.scene, options);
  const gen::CameraPath first = gen::loadCameraPath(out + "/first.json");
  const gen::CameraPath second = gen::loadCameraPath(out + "/second.json");
  ASSERT_EQ(first.frames.size(), c.path.frames.size());
  ASSERT_EQ(second.frames.size(), c.path.frames.size());
  const auto same = [](const gen::PathFrame& a, const gen::PathFrame& b) {
    return glm::length(a.eye - b.eye) < 1e-4f && glm::length(a.at - b.at) < 1e-4f &&
           glm::length(a.up - b.up) < 1e-4f && std::abs(a.fov_y - b.fov_y) < 1e-4f;
  };
  for (size_t i = 0; i < c.path.frames.size(); ++i) {
    EXPECT_TRUE(same(first.frames[i], c.path.frames[i])) << "frame " << i;
    EXPECT_TRUE(same(second.frames[i], first.frames[i])) << "frame " << i;
  }
}

TEST(Viewer, ABadDatabaseIsAnErrorNamingTheFile) {
  FF_REQUIRE_DISPLAY();
  const test::ViewCity& c = test::viewCity();
  const fs::path dir = farfield::test::scratchDir("view_bad_db");
  ViewerOptions options = scripted(dir.string(), "");
  options.impostors = (dir / "missing.imp").string();
  EXPECT_NE(errorOf(c.city.scene, options).find("missing.imp"), std::string::npos);

  // A copy of the store with its index cut in half.
  const fs::path copy = dir / "cut.imp";
  fs::copy(c.store, copy, fs::copy_options::recursive);
  const fs::path index = copy / "index.json";
  fs::resize_file(index, fs::file_size(index) / 2);
  options.impostors = copy.string();
  const std::string error = errorOf(c.city.scene, options);
  EXPECT_NE(error.find("index.json"), std::string::npos) << error;

  // A placement database with a garbled index.
  const fs::path placed = dir / "bad.place";
  fs::create_directories(placed);
  std::ofstream(placed / "placement.json") << "{\"format\": \"farfield-placement\", \"vers";
  options.impostors = placed.string();
  EXPECT_NE(errorOf(c.city.scene, options).find("placement.json"), std::string::npos);

  // A mode the database does not offer.
  options.impostors = c.store;
  options.mode = "placed";
  EXPECT_NE(errorOf(c.city.scene, options).find("placed"), std::string::npos);
}

}  // namespace
}  // namespace farfield::view
