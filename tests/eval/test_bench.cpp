#include "farfield/eval/bench.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <regex>
#include <set>
#include <sstream>
#include <thread>

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
  // No bound anywhere; popping measured (frames 2 and 3) and 0 for modes that draw what the reference draws.
  for (const char* mode : {"full", "culled"}) {
    const auto& m = j.at("modes").at(mode);
    EXPECT_TRUE(m.at("error_bound_px").is_null()) << mode;
    EXPECT_TRUE(m.at("frames_over_bound").is_null()) << mode;
    EXPECT_DOUBLE_EQ(m.at("popping_max").get<double>(), 0.0) << mode;
  }
  // The allocator settings of the run are stated (this test binary never configures them: the defaults).
  ASSERT_TRUE(j.at("allocator").is_object());
  EXPECT_EQ(j.at("allocator").at("applied"), false);
  EXPECT_NE(j.at("allocator").at("description").get<std::string>().find("defaults"), std::string::npos);
}

// summarizeModeResult over made-up frames: which bound applies and which frames break it.
ModeResult madeUpFrames(std::vector<double> parallax) {
  ModeResult m;
  m.name = "made-up";
  for (size_t k = 0; k < parallax.size(); ++k) {
    FrameRecord f;
    f.path_frame = k;
    f.wall_ms = 1.0 + double(k);
    m.frames.push_back(f);
    m.errors.push_back(image::ImageMetrics{40.0, 1.0, 0.99, 0.01});
    m.crack_shares.push_back(0.0);
  }
  m.parallax_px = std::move(parallax);
  return m;
}

TEST(BenchBound, FramesOverTheGivenBound) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  ModeResult m = madeUpFrames({0.5, 2.0, nan, 1.0, 3.5});
  summarizeModeResult(m, 1.0);
  ASSERT_TRUE(m.error_bound_px.has_value());
  EXPECT_DOUBLE_EQ(*m.error_bound_px, 1.0);
  EXPECT_EQ(m.error_bound_source, "--error-px");
  // 1.0 px is within a 1.0 px bound; the frame whose parallax could not be measured is not checked.
  EXPECT_EQ(m.over_bound, (std::vector<int>{0, 1, -1, 0, 1}));
  EXPECT_EQ(m.frames_over_bound, 2u);
  EXPECT_EQ(m.frames_checked, 4u);
}

TEST(BenchBound, AGovernedFrameIsCheckedAgainstTheBoundItKept) {
  ModeResult m = madeUpFrames({1.5, 1.5, 2.5});
  for (FrameRecord& f : m.frames) f.governor_level = 0;
  m.frames[1].governor_level = m.frames[2].governor_level = 1;
  m.frames[1].bound_scale = m.frames[2].bound_scale = 2.0;  // drawn at half the resolution: a 2 px bound kept
  summarizeModeResult(m, 1.0);
  EXPECT_EQ(m.over_bound, (std::vector<int>{1, 0, 1}));
  EXPECT_TRUE(m.governed);
  EXPECT_EQ(m.frames_relaxed, 2u);
  EXPECT_DOUBLE_EQ(m.bound_scale_max, 2.0);
  ModeResult plain = madeUpFrames({0.5});
  summarizeModeResult(plain, 1.0);
  EXPECT_FALSE(plain.governed);
  EXPECT_EQ(plain.frames_relaxed, 0u);
}

TEST(BenchBound, TheModesOwnBoundUnlessOneIsGiven) {
  ModeResult m = madeUpFrames({0.5, 2.0, 0.1});
  m.info["error_bound_px"] = 0.25;
  summarizeModeResult(m, std::nullopt);
  ASSERT_TRUE(m.error_bound_px.has_value());
  EXPECT_DOUBLE_EQ(*m.error_bound_px, 0.25);
  EXPECT_EQ(m.error_bound_source, "mode");
  EXPECT_EQ(m.over_bound, (std::vector<int>{1, 1, 0}));
  EXPECT_EQ(m.frames_over_bound, 2u);
  // --error-px wins over the mode's.
  summarizeModeResult(m, 3.0);
  EXPECT_EQ(m.error_bound_source, "--error-px");
  EXPECT_EQ(m.frames_over_bound, 0u);
  EXPECT_EQ(m.frames_checked, 3u);
  // Neither: no bound, nothing checked.
  m.info.clear();
  summarizeModeResult(m, std::nullopt);
  EXPECT_FALSE(m.error_bound_px.has_value());
  EXPECT_EQ(m.over_bound, (std::vector<int>{-1, -1, -1}));
  EXPECT_EQ(m.frames_checked, 0u);
  // Without a reference there is no parallax: a bound checks nothing.
  ModeResult plain;
  plain.frames.resize(2);
  summarizeModeResult(plain, 1.0);
  EXPECT_EQ(plain.frames_checked, 0u);
  EXPECT_EQ(plain.over_bound, (std::vector<int>{-1, -1}));
}

// A representation switch: until path frame kSwitchFrame the mode draws the scene from a camera 1 m above the
// frame's (an "impostor" with parallax), from then on the scene itself. It reports a 1 px error bound.
constexpr size_t kSwitchFrame = 5;
class SwitchMode final : public Mode {
 public:
  std::string name() const override { return "test-switch"; }
  void prepare(const ModeContext& context) override { items_ = context.gpu_scene->drawItems(); }
  void frame(FrameContext& frame) override {
    if (frame.pathFrame() >= kSwitchFrame) {
      frame.submit(items_);
      return;
    }
    Camera raised = frame.camera();
    raised.eye.z += 1.0f;
    raised.at.z += 1.0f;
    gpu::RenderTarget& target = frame.beginOwnPass();
    frame.addStats(frame.renderer().draw(raised, items_, target));
  }
  std::map<std::string, double> info() const override { return {{"error_bound_px", 1.0}}; }

 private:
  std::vector<gpu::DrawItem> items_;
};
const RegisterMode register_switch("test-switch", "test: a representation switch at path frame 5",
                                   [](const ModeContext&) { return std::make_unique<SwitchMode>(); });

TEST(BenchBound, ASwitchPopsOnceAndItsFramesBeforeBreakTheBound) {
  const fs::path dir = test::scratchDir("eval_bench_switch");
  const scene::Scene scene = scene::builtinScene("cubes");
  BenchOptions options;
  options.modes = {"test-switch"};
  options.width = 96;
  options.height = 64;
  options.frames = 10;
  options.reference = true;
  options.samples = 0;
  BenchResult result = runBench(gpu::sharedHeadlessContext(), scene, test::sideWalkPath(16), options);
  const ModeResult* m = result.mode("test-switch");
  ASSERT_NE(m, nullptr);
  ASSERT_EQ(m->popping.size(), 10u);
  ASSERT_EQ(m->over_bound.size(), 10u);
  // The bound is the mode's; the raised frames break it, the exact ones keep it.
  ASSERT_TRUE(m->error_bound_px.has_value());
  EXPECT_EQ(m->error_bound_source, "mode");
  for (size_t k = 0; k < 10; ++k)
    EXPECT_EQ(m->over_bound[k], k < kSwitchFrame ? 1 : 0) << "frame " << k << ": " << m->parallax_px[k] << " px";
  EXPECT_EQ(m->frames_over_bound, kSwitchFrame);
  EXPECT_EQ(m->frames_checked, 10u);
  // Popping peaks at the switch; after it the mode draws what the reference does (0 exactly).
  EXPECT_TRUE(std::isnan(m->popping[0]));
  for (size_t k = 1; k < 10; ++k) {
    if (k == kSwitchFrame) continue;
    EXPECT_LT(m->popping[k], m->popping[kSwitchFrame] / 4.0) << k;
    if (k > kSwitchFrame) {
      EXPECT_EQ(m->popping[k], 0.0) << k;
    }
  }
  EXPECT_GT(m->popping[kSwitchFrame], 1.0);
  EXPECT_DOUBLE_EQ(m->popping_summary.max, m->popping[kSwitchFrame]);
  // "full" draws the reference: no popping, no bound.
  EXPECT_DOUBLE_EQ(result.mode("full")->popping_summary.max, 0.0);
  EXPECT_FALSE(result.mode("full")->error_bound_px.has_value());

  // A bound given for the run applies to every mode and shows in every output.
  options.error_px = 50.0;
  result = runBench(gpu::sharedHeadlessContext(), scene, test::sideWalkPath(16), options);
  EXPECT_EQ(result.mode("test-switch")->frames_over_bound, 0u);
  EXPECT_EQ(result.mode("full")->error_bound_source, "--error-px");
  writeBenchOutputs(result, dir.string());
  const nlohmann::json j = nlohmann::json::parse(readText(dir / "bench.json"));
  EXPECT_DOUBLE_EQ(j.at("modes").at("full").at("error_bound_px").get<double>(), 50.0);
  EXPECT_EQ(j.at("modes").at("test-switch").at("frames_over_bound"), 0);
  EXPECT_EQ(j.at("modes").at("test-switch").at("frames_checked_against_bound"), 10);
  EXPECT_GT(j.at("modes").at("test-switch").at("popping_max").get<double>(), 1.0);
  const std::string md = readText(dir / "bench.md");
  EXPECT_NE(md.find("| 50.00 | 0 of 10 |"), std::string::npos) << md;
  const auto csv = lines(readText(dir / "frames.csv"));
  ASSERT_EQ(csv.size(), 1u + 10u * 2u);
  for (size_t i = 1; i < csv.size(); ++i) {
    std::vector<std::string> cells;
    std::stringstream row(csv[i]);
    for (std::string cell; std::getline(row, cell, ',');) cells.push_back(cell);
    ASSERT_GE(cells.size(), 14u) << csv[i];
    EXPECT_EQ(cells[13], "0") << csv[i];  // over_bound
  }

  options.error_px = -1.0;
  EXPECT_THROW(runBench(gpu::sharedHeadlessContext(), scene, test::sideWalkPath(4), options), Error);
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
    // GPU time on every frame, whatever the mode's position (it alternated between near 0 and the real value).
    for (const ModeResult& m : run.result.modes) {
      EXPECT_GT(m.frames[k].gpu_ms, 0.0) << m.name << " frame " << k;
      EXPECT_LE(m.frames[k].gpu_ms, m.frames[k].wall_ms) << m.name << " frame " << k;
    }
    // The first mode of frame k is mode k mod 2: the order rotates by one each frame.
    EXPECT_EQ(run.result.modes[k % 2].order[k], 0);
  }
}

// A mode that logs its renders in a shared log and is slow on its first render of every frame.
class LoggingMode : public Mode {
 public:
  LoggingMode(std::string name, std::vector<std::pair<std::string, size_t>>& log) : name_(std::move(name)), log_(log) {}
  std::string name() const override { return name_; }
  void frame(FrameContext& frame) override {
    size_t before = 0;
    for (const auto& entry : log_) before += entry == std::make_pair(name_, frame.pathFrame());
    log_.emplace_back(name_, frame.pathFrame());
    if (before == 0) std::this_thread::sleep_for(std::chrono::milliseconds(40));
  }

 private:
  std::string name_;
  std::vector<std::pair<std::string, size_t>>& log_;
};

// With repeats, a frame's renders are whole passes over the path apart (so a slow spell of the machine cannot slow
// all of a mode's renders of it), each pass in the path's order, and the fastest of them is kept.
TEST(Bench, RepeatsArePassesOverThePathAndTheFastestIsKept) {
  static std::vector<std::pair<std::string, size_t>> log;
  log.clear();
  for (const char* name : {"test-log-a", "test-log-b"})
    registerMode(name, "a test mode", [name](const ModeContext&) { return std::make_unique<LoggingMode>(name, log); });
  const scene::Scene scene = scene::builtinScene("cubes");
  BenchOptions options;
  options.modes = {"test-log-a", "test-log-b"};
  options.width = 32;
  options.height = 32;
  options.frames = 3;
  options.repeats = 3;
  options.out_dir = test::scratchDir("eval_bench_repeats").string();
  const BenchResult result = runBench(gpu::sharedHeadlessContext(), scene, test::sideWalkPath(3), options);
  ASSERT_EQ(result.modes.size(), 3u);  // full, a, b
  // Per logging mode: the warm-up frame once, then 3 renders of each of the 3 frames.
  EXPECT_EQ(log.size(), 2u * (1 + 3 * 3));
  // After the warm-up (2 renders): 3 passes of 3 frames x 2 modes, each the path in order.
  const std::vector<size_t> frames = result.frame_indices;
  ASSERT_EQ(frames.size(), 3u);
  for (size_t i = 2; i < log.size(); ++i) {
    const size_t at = i - 2;  // position in the passes
    EXPECT_EQ(log[i].second, frames[(at % 6) / 2]) << "render " << i;
    if (at >= 6) {
      EXPECT_TRUE(log[i] == log[i - 6]) << "render " << i << ": not a pass after the same render";
    }
  }
  for (size_t m = 1; m < 3; ++m)
    for (const FrameRecord& f : result.modes[m].frames)
      EXPECT_LT(f.wall_ms, 40.0) << result.modes[m].name << " frame " << f.path_frame << ": not the fastest render";
}

TEST(Bench, CsvMarkdownAndSampleFrames) {
  const ShortRun& run = shortRun();
  const auto csv = lines(readText(run.dir / "frames.csv"));
  ASSERT_EQ(csv.size(), 1u + 3u * 2u);
  EXPECT_EQ(csv[0].rfind("frame,path_frame,mode,order,wall_ms,gpu_ms,triangles", 0), 0u);
  EXPECT_NE(csv[0].find(",parallax_p99_px,over_bound,popping"), std::string::npos) << csv[0];
  EXPECT_NE(csv[0].find(",popping,cpu_ms,driver_ms,gl_calls,dispatches,upload_bytes,syncs,governor_level,predicted_ms,"
                        "corrected_ms,bound_scale,impostors"),
            std::string::npos)
      << csv[0];
  const auto field = [](const std::string& line, size_t k) {
    size_t start = 0;
    for (size_t i = 0; i < k; ++i) start = line.find(',', start) + 1;
    return line.substr(start, line.find(',', start) - start);
  };
  for (size_t i = 1; i < csv.size(); ++i) {
    EXPECT_EQ(std::count(csv[i].begin(), csv[i].end(), ','), 25) << csv[i];  // 26 columns
    // The GL counters are on in the bench: every frame has its calls counted, and culled waits for nothing.
    EXPECT_GT(std::stoul(field(csv[i], 17)), 0u) << csv[i];
    if (csv[i].find(",culled,") != std::string::npos) {
      EXPECT_EQ(field(csv[i], 20), "0") << csv[i];
    }
    // No bound for full and culled (no --error-px, neither reports one): the over_bound column says "-".
    EXPECT_NE(csv[i].find(",-,"), std::string::npos) << csv[i];
  }
  // Popping: empty for the first measured frame, a number after (0 here: both modes draw what the reference does).
  EXPECT_EQ(field(csv[1], 14), "") << csv[1];
  EXPECT_NE(field(csv.back(), 14), "") << csv.back();

  const std::string md = readText(run.dir / "bench.md");
  EXPECT_NE(md.find("| mode |"), std::string::npos);
  EXPECT_NE(md.find("| full |"), std::string::npos);
  EXPECT_NE(md.find("| culled |"), std::string::npos);
  EXPECT_NE(md.find("baseline"), std::string::npos);  // says that full was added
  EXPECT_NE(md.find("99 dB"), std::string::npos);     // says how identical frames are stored
  EXPECT_NE(md.find("frames over bound"), std::string::npos);
  EXPECT_NE(md.find("popping max"), std::string::npos);
  EXPECT_NE(md.find("- allocator: "), std::string::npos);

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
  const std::vector<std::string> rows = lines(readText(dir / "walk.csv"));
  EXPECT_EQ(rows.size(), 6u);
  const auto columns = [](const std::string& row) { return std::count(row.begin(), row.end(), ',') + 1; };
  for (const std::string& row : rows) EXPECT_EQ(columns(row), columns(rows[0])) << row;
  EXPECT_TRUE(rows[1].ends_with(",,,,")) << rows[1];  // no governor: its columns empty
  const std::string summary = formatWalkSummary(result);
  EXPECT_NE(summary.find("p99"), std::string::npos);
  EXPECT_NE(summary.find("culled"), std::string::npos);

  // Governed: each row has the level the frame was drawn at and its prediction.
  WalkOptions governed = options;
  governed.mode = "governed";
  governed.frames_dir.clear();
  governed.mode_options = {{"governor_t_max_ms", "1000"}};
  const WalkResult g = runWalk(gpu::sharedHeadlessContext(), scene, test::sideWalkPath(3), governed);
  writeWalkCsv(g, (dir / "governed.csv").string());
  const std::vector<std::string> g_rows = lines(readText(dir / "governed.csv"));
  ASSERT_EQ(g_rows.size(), 4u);
  EXPECT_NE(g_rows[0].find("governor_level,predicted_ms"), std::string::npos);
  for (size_t k = 1; k < g_rows.size(); ++k) {
    EXPECT_EQ(columns(g_rows[k]), columns(g_rows[0])) << g_rows[k];
    EXPECT_FALSE(g_rows[k].ends_with(",,,,")) << g_rows[k];
  }

  options.mode = "nope";
  EXPECT_THROW(runWalk(gpu::sharedHeadlessContext(), scene, test::sideWalkPath(2), options), Error);
}

}  // namespace
}  // namespace farfield::eval
