// The LOD-sprite terrain experiment (eval/terrain_bench.h) end to end on a small fractal terrain (GL: headless
// llvmpipe, 128x128 frames, 24 frames): every file written, the keyframes where the render-free simulation of the
// error metric puts them, every frame's sprite within the threshold, lod-sprite closer to high than low is; and bad
// options (no GL) rejected naming the option before anything is loaded or written.
#include "farfield/eval/terrain_bench.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <numeric>
#include <sstream>

#include <nlohmann/json.hpp>

#include "farfield/core/error.h"
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

size_t lineCount(const fs::path& file) {
  const std::string text = readText(file);
  return size_t(std::count(text.begin(), text.end(), '\n'));
}

constexpr size_t kFrames = 24;

TerrainBenchOptions smallOptions(const fs::path& out) {
  TerrainBenchOptions o;
  o.dem = "fractal:129:3";
  o.frames = kFrames;
  o.out_dir = out.string();
  o.width = o.height = 128;
  o.block = 32;
  o.sweep_epsilons = {0.5, 2.0};
  o.sweep_frames = {12, 36};
  o.plots = false;
  o.log = nullptr;
  return o;
}

// One run per test process (ctest runs each test in its own process).
struct SmallRun {
  fs::path out;
  TerrainBenchOptions options;
  TerrainBenchResult result;
};
const SmallRun& smallRun() {
  static const SmallRun run = [] {
    SmallRun r;
    r.out = test::scratchDir("terrain_bench");
    r.options = smallOptions(r.out);
    r.result = runTerrainBench(r.options);
    return r;
  }();
  return run;
}

TEST(TerrainBenchGL, WritesEveryFile) {
  const SmallRun& run = smallRun();
  const fs::path& out = run.out;
  for (const char* f : {"path.json", "bench.json", "bench.md", "frames.csv", "report.md", "terrain.json", "terrain.md"})
    EXPECT_GT(fs::file_size(out / f), 0u) << f;
  const fs::path fig = out / "figures";
  for (int view = 1; view <= 2; ++view)
    for (const char* part : {"a_low", "b_high", "c_lod_sprite", "d_diff_low_high", "e_diff_high_lod_sprite"}) {
      const fs::path png = fig / "fig06" / ("view" + std::to_string(view) + "_" + part + ".png");
      EXPECT_TRUE(fs::exists(png)) << png;
    }
  EXPECT_TRUE(fs::exists(fig / "fig08_terrain.png"));
  // One header line, then a line per frame (per path frame for Figure 8, per view for Figure 6, per row otherwise).
  EXPECT_EQ(lineCount(fig / "fig06_views.csv"), 1u + 2u);
  EXPECT_EQ(lineCount(fig / "fig08_path.csv"), 1u + kFrames);
  for (const char* f : {"fig09_triangles.csv", "fig10_error.csv", "fig11_time.csv", "quality.csv"})
    EXPECT_EQ(lineCount(fig / f), 1u + kFrames) << f;
  EXPECT_EQ(lineCount(fig / "fig12_keyframes_vs_frames.csv"), 1u + 2u);
  EXPECT_EQ(lineCount(fig / "fig13_keyframes_vs_epsilon.csv"), 1u + 2u);
  EXPECT_EQ(lineCount(fig / "fig14_speedup_vs_epsilon.csv"), 1u + 2u);
  EXPECT_EQ(lineCount(fig / "section5_back_and_forth.csv"), 1u + 4u);

  const nlohmann::json summary = nlohmann::json::parse(readText(out / "terrain.json"));
  EXPECT_EQ(summary["frames"].get<size_t>(), kFrames);
  EXPECT_EQ(summary["terrain"].get<std::string>(), run.result.terrain);
  EXPECT_TRUE(summary["cost_model"]["frame"].contains("ms_per_mtriangle"));
  for (const char* m : {"full", "high", "low", "lod-sprite", "lod-sprite-always", "lod-sprite-predict",
                        "lod-sprite-cache"})
    EXPECT_TRUE(summary["modes"].contains(m)) << m;
  EXPECT_EQ(summary["sweeps"]["epsilon"].size(), 2u);
  EXPECT_EQ(summary["sweeps"]["keyframes_vs_frames"].size(), 2u);
  EXPECT_EQ(summary["section5_back_and_forth"].size(), 4u);
  const nlohmann::json bench = nlohmann::json::parse(readText(out / "bench.json"));
  EXPECT_TRUE(bench["modes"]["lod-sprite"]["info"].contains("psnr_vs_high_db_mean"));
  EXPECT_EQ(readText(out / "terrain.md"), run.result.markdown);
  EXPECT_NE(run.result.markdown.find("| lod-sprite |"), std::string::npos);
}

// docs/BENCHMARKS.md: the measured keyframes equal a render-free simulation of the metric. Here frame by frame, in
// the harness's timed pass and at every threshold of the sweep.
TEST(TerrainBenchGL, KeyframesAreWhereTheSimulationPutsThem) {
  const TerrainBenchResult& r = smallRun().result;
  ASSERT_EQ(r.sprite_log.size(), kFrames);
  ASSERT_EQ(r.keyframes_simulated.size(), kFrames);
  // With the per-frame choice (terrain/path_choice.h) a trip of the metric is a rendered keyframe or a virtual one
  // (the frame drew the high LOD); a keyframe is rendered only at a trip or at a switch (the virtual keyframe's age
  // made one pay). Until the first switch the trips are the simulation's; lod-sprite-always, the paper's technique,
  // has a keyframe at every simulated one.
  size_t keyframes = 0, fresh_keyframes = 0;
  bool switched = false;
  for (size_t k = 0; k < kFrames; ++k) {
    const terrain::LodSpriteFrameInfo& info = r.sprite_log[k].info;
    const bool fresh = info.source == terrain::SpriteSource::Fresh;
    switched = switched || info.switched;
    if (!switched) {
      EXPECT_EQ(info.keyframe_due, r.keyframes_simulated[k] != 0) << "frame " << k;
    }
    if (fresh) {
      EXPECT_TRUE(info.keyframe_due || info.switched) << "frame " << k;
    }
    keyframes += r.keyframes_simulated[k];
    fresh_keyframes += fresh;
  }
  // Not trivially true: the first frame is a keyframe, some later frame is one, and some frame reuses a sprite.
  EXPECT_TRUE(r.keyframes_simulated[0]);
  EXPECT_GE(keyframes, 2u);
  EXPECT_LT(keyframes, kFrames);
  const ModeResult* sprite = r.bench.mode("lod-sprite");
  ASSERT_NE(sprite, nullptr);
  EXPECT_EQ(sprite->info.at("keyframes"), double(fresh_keyframes));
  // lod-sprite-always is the paper's technique: a keyframe at every trip.
  const ModeResult* always = r.bench.mode("lod-sprite-always");
  ASSERT_NE(always, nullptr);
  EXPECT_EQ(always->info.at("keyframes"), double(keyframes));
  EXPECT_EQ(always->info.at("high_frames"), 0.0);

  ASSERT_EQ(r.epsilon_sweep.size(), 2u);
  for (const EpsilonSweepRow& row : r.epsilon_sweep) {
    if (row.switches == 0) {
      EXPECT_EQ(row.keyframes, row.keyframes_simulated) << "epsilon " << row.epsilon_px;
    }
    EXPECT_GE(row.keyframes, 1u);
  }
  ASSERT_EQ(r.keyframes_vs_frames.size(), 2u);
  EXPECT_EQ(r.keyframes_vs_frames[0].frames, 12u);
  EXPECT_EQ(r.keyframes_vs_frames[1].frames, 36u);
}

// Equation 2's promise: every frame is drawn from a sprite whose error at the frame's viewpoint is under the
// threshold (a fresh keyframe has none), and a new keyframe is taken exactly when the old sprite reached it.
TEST(TerrainBenchGL, EverySpriteIsWithinTheThreshold) {
  const SmallRun& run = smallRun();
  const double epsilon = run.options.epsilon;
  for (size_t k = 0; k < run.result.sprite_log.size(); ++k) {
    const terrain::LodSpriteFrameInfo& info = run.result.sprite_log[k].info;
    EXPECT_LT(info.error_px, epsilon) << "frame " << k;
    if (k > 0 && info.source == terrain::SpriteSource::Fresh && !info.switched) {
      EXPECT_GE(info.trigger_error_px, epsilon) << "frame " << k;
    }
    if (info.source == terrain::SpriteSource::Kept) {
      EXPECT_LT(info.trigger_error_px, epsilon) << "frame " << k;
    }
  }
}

// docs/BENCHMARKS.md: LOD-sprite frames are closer to the high-resolution frames than the low-resolution frames are.
TEST(TerrainBenchGL, LodSpriteIsCloserToHighThanLowIs) {
  const TerrainBenchResult& r = smallRun().result;
  ASSERT_EQ(r.quality.size(), kFrames);
  ASSERT_TRUE(r.psnr_mean.count("low") && r.psnr_mean.count("lod-sprite"));
  EXPECT_GT(r.psnr_mean.at("lod-sprite"), r.psnr_mean.at("low"));
  EXPECT_LT(r.psnr_mean.at("low"), kPsnrCapDb);  // the low LOD differs from the high one on this terrain
  // Against the full-resolution grid (drawn: this terrain is small), the 1 px LOD is closer than the 4 px one.
  ASSERT_TRUE(r.psnr_full_mean.count("high") && r.psnr_full_mean.count("low"));
  EXPECT_GT(r.psnr_full_mean.at("high"), r.psnr_full_mean.at("low"));
  EXPECT_LT(r.psnr_full_mean.at("high"), kPsnrCapDb);
  for (const char* variant : {"lod-sprite-always", "lod-sprite-predict", "lod-sprite-cache"}) {
    ASSERT_TRUE(r.psnr_mean.count(variant)) << variant;
    EXPECT_GT(r.psnr_mean.at(variant), r.psnr_mean.at("low")) << variant;
  }
}

TEST(TerrainBenchGL, WithoutSweepsOnlyTheirFilesAreMissing) {
  const fs::path out = test::scratchDir("terrain_bench_no_sweeps");
  TerrainBenchOptions o = smallOptions(out);
  o.frames = 8;
  o.quality_stride = 3;
  o.sweeps = false;
  o.modes = {"high", "low", "lod-sprite"};
  const TerrainBenchResult r = runTerrainBench(o);
  EXPECT_TRUE(r.epsilon_sweep.empty() && r.keyframes_vs_frames.empty() && r.back_and_forth.empty());
  EXPECT_TRUE(fs::exists(out / "figures" / "fig11_time.csv"));
  for (const char* f : {"fig12_keyframes_vs_frames.csv", "fig13_keyframes_vs_epsilon.csv",
                        "fig14_speedup_vs_epsilon.csv", "section5_back_and_forth.csv"})
    EXPECT_FALSE(fs::exists(out / "figures" / f)) << f;
  // Frames 0, 3, 6 and Figure 6's two views (path frames 3 and 5).
  EXPECT_EQ(r.quality.size(), 4u);
  const nlohmann::json summary = nlohmann::json::parse(readText(out / "terrain.json"));
  EXPECT_TRUE(summary["sweeps"].is_null());
  EXPECT_EQ(summary["modes"].size(), 4u);  // full, high, low, lod-sprite
}

// lod-sprite-tiles (with the per-frame choice) and lod-sprite-tiles-always run through the harness and the quality
// pass like the other modes, with Figure 6's views written for both.
TEST(TerrainBenchGL, TileSpritesAreTimedAndMeasured) {
  const fs::path out = test::scratchDir("terrain_bench_tiles");
  TerrainBenchOptions o = smallOptions(out);
  o.modes = {"high", "low", "lod-sprite", "lod-sprite-tiles", "lod-sprite-tiles-always"};
  o.sweeps = false;
  o.sprite_tile_cells = 32;
  const TerrainBenchResult result = runTerrainBench(o);
  const nlohmann::json bench = nlohmann::json::parse(readText(out / "bench.json"));
  for (const char* mode : {"lod-sprite-tiles", "lod-sprite-tiles-always"}) {
    const nlohmann::json& info = bench["modes"][mode]["info"];
    EXPECT_EQ(info["tile_cells"].get<double>(), 32.0) << mode;
    EXPECT_EQ(info["frames"].get<double>(), double(kFrames)) << mode;
    EXPECT_LE(info["tile_keyframes"].get<double>(), info["tile_frames_in_view"].get<double>()) << mode;
    ASSERT_TRUE(result.psnr_mean.count(mode));
    EXPECT_GT(result.psnr_mean.at(mode), result.psnr_mean.at("low")) << mode;
    for (const char* view : {"view1", "view2"}) {
      EXPECT_TRUE(fs::exists(out / "figures" / "fig06" / (std::string(view) + "_f_" + mode + ".png"))) << mode;
    }
  }
  // The tiles on every frame render keyframes and never the high LOD; with the choice the first frame is the high
  // LOD (its size is learnt from one frame).
  const nlohmann::json& always = bench["modes"]["lod-sprite-tiles-always"]["info"];
  EXPECT_GT(always["tile_keyframes"].get<double>(), 0.0);
  EXPECT_GT(always["sprite_triangle_share"].get<double>(), 0.0);
  EXPECT_EQ(always["high_frames"].get<double>(), 0.0);
  EXPECT_GE(bench["modes"]["lod-sprite-tiles"]["info"]["high_frames"].get<double>(), 1.0);
}

// Bad options: farfield::Error naming the option, before the terrain is loaded or a file written.
TEST(TerrainBench, BadOptionsNameTheOption) {
  const fs::path out = test::scratchDir("terrain_bench_bad") / "out";
  const std::vector<std::pair<std::string, std::function<void(TerrainBenchOptions&)>>> cases{
      {"dem", [](TerrainBenchOptions& o) { o.dem.clear(); }},
      {"--output", [](TerrainBenchOptions& o) { o.out_dir.clear(); }},
      {"--size", [](TerrainBenchOptions& o) { o.width = 0; }},
      {"--epsilon", [](TerrainBenchOptions& o) { o.epsilon = 0.0; }},
      {"--high-error/--low-error", [](TerrainBenchOptions& o) { o.high_error = 5.0f; }},
      {"--high-error/--low-error", [](TerrainBenchOptions& o) { o.high_error = 0.0f; }},
      {"--quality-stride", [](TerrainBenchOptions& o) { o.quality_stride = 0; }},
      {"--frames", [](TerrainBenchOptions& o) { o.frames = 1; }},
      // Counts the flythrough's int cannot hold (it used to be an int conversion, then an allocation failure).
      {"--frames", [](TerrainBenchOptions& o) { o.frames = size_t(5) << 30; }},
      {"--sweep-frames", [](TerrainBenchOptions& o) { o.sweep_frames = {75, size_t(1) << 40}; }},
      {"--modes", [](TerrainBenchOptions& o) { o.modes = {"high", "low"}; }},
      {"mode 'no-such-mode'", [](TerrainBenchOptions& o) { o.modes.push_back("no-such-mode"); }},
      {"--sweep-epsilons", [](TerrainBenchOptions& o) { o.sweep_epsilons = {1.0, -2.0}; }},
      {"--block", [](TerrainBenchOptions& o) { o.block = 0; }},
      {"--sprite-tile-cells", [](TerrainBenchOptions& o) { o.sprite_tile_cells = 0; }},
  };
  for (const auto& [name, spoil] : cases) {
    TerrainBenchOptions o = smallOptions(out);
    o.dem = "fractal:not-a-size";  // loading it would fail with another message
    spoil(o);
    try {
      runTerrainBench(o);
      ADD_FAILURE() << name << ": no error";
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()).rfind(name + ":", 0), 0u) << name << " -> " << e.what();
    }
  }
  EXPECT_FALSE(fs::exists(out));
  // The options themselves are good: only the DEM is bad, and its error names it.
  TerrainBenchOptions o = smallOptions(out);
  o.dem = "fractal:not-a-size";
  try {
    runTerrainBench(o);
    ADD_FAILURE() << "bad DEM: no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("fractal:not-a-size"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace farfield::eval
