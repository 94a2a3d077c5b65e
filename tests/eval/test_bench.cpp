#include "farfield/eval/bench.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "eval/eval_test_scenes.h"
#include "farfield/core/error.h"
#include "farfield/eval/walk.h"
#include "farfield/gpu/context.h"
#include "farfield/image/png_io.h"
#include "farfield/scene/builtin.h"
#include "support/test_support.h"

namespace fs = std::filesystem;

namespace farfield::eval {
namespace {

std::string readText(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  for (std::string line; std::getline(ss, line);)
    if (!line.empty()) out.push_back(line);
  return out;
}

// One short run shared by the tests below: 3 frames at 64x64, "culled" asked for ("full" is added), reference on.
struct ShortRun {
  fs::path dir;
  scene::Scene scene = scene::builtinScene("cubes");
  gen::CameraPath path = test::sideWalkPath(5);
  BenchResult result;

  ShortRun() {
    dir = test::scratchDir("eval_bench");
    BenchOptions options;
    options.modes = {"culled"};
    options.width = 64;
    options.height = 64;
    options.frames = 3;
    options.stride = 2;  // path frames 0, 2, 4
    options.reference = true;
    options.samples = 2;
    options.out_dir = dir.string();
    options.scene_label = "builtin:cubes";
    options.path_label = "side walk (test)";
    result = runBench(gpu::sharedHeadlessContext(), scene, path, options);
    writeBenchOutputs(result, dir.string());
  }
};

const ShortRun& shortRun() {
  static ShortRun run;
  return run;
}

TEST(Bench, JsonHasEveryKeyForEveryMode) {
  const ShortRun& run = shortRun();
  const nlohmann::json j = nlohmann::json::parse(readText(run.dir / "bench.json"));
  EXPECT_EQ(j.at("scene"), "builtin:cubes");
  EXPECT_EQ(j.at("frames"), 3);
  EXPECT_EQ(j.at("size"), nlohmann::json::array({64, 64}));
  EXPECT_TRUE(j.at("renderer").is_string());
  EXPECT_FALSE(j.at("renderer").get<std::string>().empty());
  EXPECT_TRUE(j.at("date").is_string());
  EXPECT_TRUE(j.at("machine").is_object());
  EXPECT_EQ(j.at("baseline"), "full");
  EXPECT_EQ(j.at("baseline_added"), true);
  ASSERT_TRUE(j.at("modes").is_object());
  ASSERT_EQ(j.at("modes").size(), 2u);
  const char* keys[] = {"median_ms",       "p95_ms",      "p99_ms",       "max_ms",
                        "mean_triangles",  "mean_draw_calls", "speedup_vs_full", "psnr_db_mean",
                        "psnr_db_min",     "ssim_mean",   "bad_pixel_share_mean", "gpu_median_ms"};
  for (const char* mode : {"full", "culled"}) {
    ASSERT_TRUE(j.at("modes").contains(mode)) << mode;
    const auto& m = j.at("modes").at(mode);
    for (const char* key : keys) {
      ASSERT_TRUE(m.contains(key)) << mode << "." << key;
      EXPECT_TRUE(m.at(key).is_number()) << mode << "." << key << " = " << m.at(key).dump();
      EXPECT_TRUE(std::isfinite(m.at(key).get<double>())) << mode << "." << key;
    }
    EXPECT_GT(m.at("median_ms").get<double>(), 0.0);
    EXPECT_LE(m.at("median_ms").get<double>(), m.at("p95_ms").get<double>());
    EXPECT_LE(m.at("p95_ms").get<double>(), m.at("p99_ms").get<double>());
    EXPECT_LE(m.at("p99_ms").get<double>(), m.at("max_ms").get<double>());
  }
  const auto& full = j.at("modes").at("full");
  const auto& culled = j.at("modes").at("culled");
  EXPECT_DOUBLE_EQ(full.at("speedup_vs_full").get<double>(), 1.0);
  EXPECT_NEAR(culled.at("speedup_vs_full").get<double>(),
              full.at("median_ms").get<double>() / culled.at("median_ms").get<double>(), 1e-9);
  // Full geometry against the full-geometry reference: identical frames, PSNR stored at the cap.
  EXPECT_DOUBLE_EQ(full.at("psnr_db_mean").get<double>(), kPsnrCapDb);
  EXPECT_DOUBLE_EQ(full.at("ssim_mean").get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(full.at("bad_pixel_share_mean").get<double>(), 0.0);
  // Same ids as the reference everywhere: no parallax; culling drops only what is out of view.
  EXPECT_DOUBLE_EQ(full.at("parallax_p99_px_max").get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(culled.at("parallax_p99_px_max").get<double>(), 0.0);
  EXPECT_GT(culled.at("psnr_db_min").get<double>(), 50.0);
  // 1 ground quad (2 triangles) + 25 boxes (12 each), every frame.
  EXPECT_DOUBLE_EQ(full.at("mean_triangles").get<double>(), 302.0);
  EXPECT_LT(culled.at("mean_triangles").get<double>(), 302.0);
}

TEST(Bench, FramesAreInterleavedWithRotatingOrder) {
  const ShortRun& run = shortRun();
  ASSERT_EQ(run.result.frame_indices, (std::vector<size_t>{0, 2, 4}));
  ASSERT_EQ(run.result.modes.size(), 2u);
  EXPECT_EQ(run.result.modes[0].name, "full");
  EXPECT_EQ(run.result.modes[1].name, "culled");
  for (size_t k = 0; k < 3; ++k) {
    std::set<int> positions;
    for (const ModeResult& m : run.result.modes) {
      ASSERT_EQ(m.frames.size(), 3u);
      EXPECT_EQ(m.frames[k].path_frame, run.result.frame_indices[k]);
      positions.insert(m.order[k]);
    }
    EXPECT_EQ(positions, (std::set<int>{0, 1}));  // each mode once per frame
    // The first mode of frame k is mode k mod 2: the order rotates by one each frame.
    EXPECT_EQ(run.result.modes[k % 2].order[k], 0);
  }
}

TEST(Bench, CsvMarkdownAndSampleFrames) {
  const ShortRun& run = shortRun();
  const auto csv = lines(readText(run.dir / "frames.csv"));
  ASSERT_EQ(csv.size(), 1u + 3u * 2u);
  EXPECT_EQ(csv[0].rfind("frame,path_frame,mode,order,wall_ms,gpu_ms,triangles", 0), 0u);
  for (size_t i = 1; i < csv.size(); ++i) EXPECT_EQ(std::count(csv[i].begin(), csv[i].end(), ','), 12) << csv[i];

  const std::string md = readText(run.dir / "bench.md");
  EXPECT_NE(md.find("| mode |"), std::string::npos);
  EXPECT_NE(md.find("| full |"), std::string::npos);
  EXPECT_NE(md.find("| culled |"), std::string::npos);
  EXPECT_NE(md.find("baseline"), std::string::npos);  // says that full was added
  EXPECT_NE(md.find("99 dB"), std::string::npos);     // says how identical frames are stored

  // Two evenly spaced samples out of three frames: the first and the last.
  ASSERT_EQ(run.result.samples.size(), 2u);
  EXPECT_EQ(run.result.samples[0].path_frame, 0u);
  EXPECT_EQ(run.result.samples[1].path_frame, 4u);
  for (const SampleFrame& s : run.result.samples) {
    const image::ColorImage reference = image::readPng((run.dir / s.reference_png).string());
    EXPECT_EQ(reference.width(), 64);
    for (const char* mode : {"full", "culled"}) {
      ASSERT_TRUE(s.mode_png.count(mode));
      ASSERT_TRUE(s.diff_png.count(mode));
      EXPECT_TRUE(fs::exists(run.dir / s.mode_png.at(mode)));
      EXPECT_TRUE(fs::exists(run.dir / s.diff_png.at(mode)));
    }
    // The saved full frame is the reference picture.
    const image::ColorImage full = image::readPng((run.dir / s.mode_png.at("full")).string());
    EXPECT_EQ(full.pixels(), reference.pixels());
  }
}

TEST(Bench, ReportLinksResolveFromTheReportsDirectory) {
  const ShortRun& run = shortRun();
  BenchResult result = run.result;
  result.plots = runPlotScript(run.dir.string(), std::string(FF_SOURCE_DIR) + "/tools/plot_bench.py");
  // Plots are optional (python3 with matplotlib may be missing); when drawn they are files in the directory.
  for (const std::string& p : result.plots) EXPECT_TRUE(fs::exists(run.dir / p)) << p;
  const fs::path report = run.dir / "elsewhere" / "report.md";
  writeReport(result, run.dir.string(), report.string());
  const std::string md = readText(report);
  EXPECT_NE(md.find("| culled |"), std::string::npos);
  const std::regex image_link(R"(!\[[^\]]*\]\(([^)]+)\))");
  size_t images = 0;
  for (auto it = std::sregex_iterator(md.begin(), md.end(), image_link); it != std::sregex_iterator(); ++it) {
    const std::string target = (*it)[1];
    EXPECT_FALSE(fs::path(target).is_absolute()) << target;
    EXPECT_TRUE(fs::exists(report.parent_path() / target)) << target;
    ++images;
  }
  // Per sample: the reference, two modes and two heat maps; plus the plots.
  EXPECT_EQ(images, 2u * 5u + result.plots.size());
}

TEST(Bench, PlotScriptMissingOnlyWarns) {
  const fs::path dir = test::scratchDir("eval_plot_missing");
  EXPECT_TRUE(runPlotScript(dir.string(), (dir / "no_such_script.py").string()).empty());
}

TEST(Bench, UnknownModeFailsBeforeRendering) {
  const scene::Scene scene = scene::builtinScene("cube");
  BenchOptions options;
  options.modes = {"culled", "warp-drive"};
  options.width = options.height = 16;
  try {
    runBench(gpu::sharedHeadlessContext(), scene, test::sideWalkPath(2), options);
    FAIL() << "no error for an unknown mode";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("warp-drive"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("culled"), std::string::npos) << e.what();
  }
  gen::CameraPath empty;
  options.modes = {"full"};
  EXPECT_THROW(runBench(gpu::sharedHeadlessContext(), scene, empty, options), Error);
}

TEST(Walk, CsvFramesAndSummary) {
  const fs::path dir = test::scratchDir("eval_walk");
  const scene::Scene scene = scene::builtinScene("cubes");
  WalkOptions options;
  options.mode = "culled";
  options.width = options.height = 48;
  options.frames_dir = (dir / "frames").string();
  options.every = 2;
  const WalkResult result = runWalk(gpu::sharedHeadlessContext(), scene, test::sideWalkPath(5), options);
  ASSERT_EQ(result.frames.size(), 5u);
  EXPECT_EQ(result.written_frames.size(), 3u);  // frames 0, 2, 4
  EXPECT_TRUE(fs::exists(dir / "frames" / "frame_00004.png"));
  double max_ms = 0.0;
  for (const FrameRecord& f : result.frames) {
    max_ms = std::max(max_ms, f.wall_ms);
    EXPECT_LT(f.triangles, 302u);
    EXPECT_GT(f.triangles, 0u);
  }
  EXPECT_DOUBLE_EQ(result.wall.max, max_ms);
  writeWalkCsv(result, (dir / "walk.csv").string());
  EXPECT_EQ(lines(readText(dir / "walk.csv")).size(), 6u);
  const std::string summary = formatWalkSummary(result);
  EXPECT_NE(summary.find("p99"), std::string::npos);
  EXPECT_NE(summary.find("culled"), std::string::npos);

  options.mode = "nope";
  EXPECT_THROW(runWalk(gpu::sharedHeadlessContext(), scene, test::sideWalkPath(2), options), Error);
}

}  // namespace
}  // namespace farfield::eval
