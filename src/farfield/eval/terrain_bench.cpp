// The LOD-sprite terrain experiment, Chen et al. 1999 sections 4 and 5 (Figures 6 and 8-14): its helpers, the path,
// the cost model, the harness, and runTerrainBench running the stages (terrain_experiment.h).
#include "farfield/eval/terrain_bench.h"

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <numeric>
#include <optional>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "farfield/core/check.h"
#include "farfield/core/checked_cast.h"
#include "farfield/core/error.h"
#include "farfield/core/log.h"
#include "farfield/core/progress.h"
#include "farfield/core/timer.h"
#include "farfield/eval/frame_runner.h"
#include "farfield/eval/terrain_paths.h"
#include "farfield/gpu/context.h"
#include "farfield/image/metrics.h"
#include "farfield/image/png_io.h"
#include "farfield/terrain/flythrough.h"
#include "farfield/terrain/lod_sprite.h"

#include "farfield/eval/terrain_experiment.h"

namespace farfield::eval {
namespace terrain_experiment {

// ---------------------------------------------------------------------------------------------------------------
// Output helpers

void say(const TerrainBenchOptions& options, const char* format, ...) {
  if (!options.log) return;
  va_list args;
  va_start(args, format);
  std::vfprintf(options.log, format, args);
  va_end(args);
}

void writeText(const fs::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary);
  if (!out) throw Error(file.string(), "cannot open for writing");
  out << text;
  if (!out) throw Error(file.string(), "write failed");
}

// Fixed decimals; "" for NaN and infinity (an empty CSV cell).
std::string num(double v, int decimals) {
  if (!std::isfinite(v)) return "";
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f", decimals, v);
  return buf;
}


// Absolute difference |a - b| per channel, scaled by `gain` (the paper's Figure 6d/e difference images).
image::ColorImage absDifference(const image::ColorImage& a, const image::ColorImage& b, int gain) {
  image::ColorImage out(a.width(), a.height());
  for (size_t k = 0; k < a.pixels().size(); ++k) {
    image::Rgba8 d;
    for (int c = 0; c < 3; ++c)
      d[c] = uint8_t(std::min(255, gain * std::abs(int(a.pixels()[k][c]) - int(b.pixels()[k][c]))));
    d.a = 255;
    out.pixels()[k] = d;
  }
  return out;
}

// Runs tools/plot_terrain.py FIGURES_DIR with the first python that has matplotlib; false when none could.
bool runTerrainPlots(const fs::path& figures, const std::string& script, const std::string& python) {
  if (script.empty()) {
    FF_WARN("tools/plot_terrain.py not found; figures have CSV only");
    return false;
  }
  std::vector<std::string> candidates;
  for (const std::string& c : {python, std::string("python3"), std::string("/usr/bin/python3")})
    if (!c.empty()) candidates.push_back(c);
  for (const std::string& py : candidates) {
    const std::string probe = "'" + py + "' -c 'import matplotlib' >/dev/null 2>&1";
    const int status = std::system(probe.c_str());
    if (status == -1 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) continue;
    std::fflush(stdout);
    const std::string command = "'" + py + "' '" + script + "' '" + figures.string() + "'";
    const int rc = std::system(command.c_str());
    if (rc != -1 && WIFEXITED(rc) && WEXITSTATUS(rc) == 0) return true;
    FF_WARN(script << " failed; figures have CSV only");
    return false;
  }
  FF_WARN("no python with matplotlib; figures have CSV only");
  return false;
}

// ---------------------------------------------------------------------------------------------------------------
// Stages

double totalMs(const ModeResult& m) {
  double t = 0.0;
  for (const FrameRecord& f : m.frames) t += f.wall_ms;
  return t;
}

// Stalls: on a shared machine a frame now and then waits seconds for the CPU (other processes). A frame where any
// mode took over max(1 s, 20x its median) is left out of every mode's "filtered" total, so all modes are summed
// over the same frames; the raw totals are reported too.
std::vector<uint8_t> stalledFrames(const BenchResult& bench) {
  std::vector<uint8_t> stalled(bench.frame_indices.size(), 0);
  for (const ModeResult& m : bench.modes)
    for (size_t k = 0; k < m.frames.size(); ++k)
      if (m.frames[k].wall_ms > std::max(1000.0, 20.0 * m.wall.median)) stalled[k] = 1;
  return stalled;
}

double filteredMs(const ModeResult& m, const std::vector<uint8_t>& stalled) {
  double t = 0.0;
  for (size_t k = 0; k < m.frames.size(); ++k)
    if (!stalled[k]) t += m.frames[k].wall_ms;
  return t;
}

// Mean of the frame times without stalls (frames over max(1 s, 20x the median)); 0 for none.
double meanWithoutStalls(const std::vector<double>& times, double median) {
  double kept = 0.0;
  size_t kept_n = 0;
  for (double t : times)
    if (t <= std::max(1000.0, 20.0 * median)) kept += t, ++kept_n;
  return kept_n ? kept / double(kept_n) : 0.0;
}

// The camera path (given, or Figure 8's kind of flythrough over this terrain) and Figure 8.
void makePath(Experiment& x) {
  const TerrainBenchOptions& o = x.options;
  x.fly.frames = checkedCast<int>(o.frames, "--frames", "frame count");
  x.fly.clearance = o.clearance;
  x.generated = o.path.empty();
  if (x.generated) {
    terrain::FlythroughLandmarks landmarks;
    x.path = flythroughCameraPath(x.data().hf, x.fly, &landmarks);
    x.result.path_file = (x.out / "path.json").string();
    gen::saveCameraPath(x.path, x.result.path_file);
    say(o,
        "path:    flythrough of %zu frames (plain (%.0f, %.0f) m, mountains (%.0f, %.0f) m, beyond (%.0f, "
        "%.0f) m), saved to %s\n",
        x.path.frames.size(), landmarks.plain.x, landmarks.plain.y, landmarks.mountains.x, landmarks.mountains.y,
        landmarks.beyond.x, landmarks.beyond.y, x.result.path_file.c_str());
  } else {
    x.path = gen::loadCameraPath(o.path);
    x.result.path_file = o.path;
    say(o, "path:    %s, %zu frames\n", o.path.c_str(), x.path.frames.size());
  }
  x.result.path_frames = x.path.frames.size();
  // Figure 8: the path over the terrain (texture north-up; extent in the terrain frame, metres).
  std::ostringstream f8;
  f8 << "frame,eye_x,eye_y,eye_z,at_x,at_y,at_z,extent_x,extent_y\n";
  for (size_t i = 0; i < x.path.frames.size(); ++i) {
    const gen::PathFrame& f = x.path.frames[i];
    f8 << i << "," << num(f.eye.x, 1) << "," << num(f.eye.y, 1) << "," << num(f.eye.z, 1) << "," << num(f.at.x, 1)
       << "," << num(f.at.y, 1) << "," << num(f.at.z, 1) << "," << num(x.data().hf.extentX(), 1) << ","
       << num(x.data().hf.extentY(), 1) << "\n";
  }
  writeText(x.figures / "fig08_path.csv", f8.str());
  terrain::writeTexturePng((x.figures / "fig08_terrain.png").string(), x.data().texture);
  x.planes = terrainClipPlanes(x.data().hf, x.path);
}

// 0. The cost model of this machine's terrain frames, from 5 frames spread over the path (untimed, before the
// harness), for lod-sprite's per-frame choice.
void calibrate(Experiment& x) {
  const TerrainBenchOptions& o = x.options;
  gpu::sharedHeadlessContext().makeCurrent();
  std::vector<Camera> views;
  const size_t n = x.path.frames.size();
  for (size_t k = 0; k < 5; ++k) views.push_back(x.cameraAt(x.path, std::min(n - 1, (2 * k + 1) * n / 10)));
  const bool gpu_sprite = std::any_of(o.modes.begin(), o.modes.end(), [](const std::string& m) {
    SpriteVariant variant;
    bool gpu = false;
    return spriteVariantOf(m, variant, &gpu) && gpu;
  });
  const terrain::TerrainCostOptions c = spriteCostOptions(*x.run, std::move(views), o.width, o.height,
                                                          gpu_sprite ? &x.run->gpuLod() : nullptr);
  x.run->cost = terrain::calibrateTerrainCost(*x.data().lod, x.run->gpuRenderer(), c);
  x.result.cost = x.run->cost;
  const gpu::CostModel& m = x.run->cost->frame;
  say(o,
      "cost:    terrain frame = %.3f ms + %.3f ms/Mtriangle + %.3f ms/draw + %.3f ms/Mpixel (r2 %.3f, rms %.3f ms); "
      "z-buffer read back %.3f ms/Mpixel\n",
      m.base_ms, m.ms_per_mtriangle, m.ms_per_draw, m.ms_per_mpixel, m.r2, m.rms_error_ms,
      x.run->cost->readback_ms_per_mpixel);
  if (const std::optional<gpu::CostModel>& g = x.run->cost->gpu_high)
    say(o, "cost:    CDLOD frame = %.3f ms + %.3f ms/Mtriangle + %.3f ms/Mpixel (r2 %.3f, rms %.3f ms)\n", g->base_ms,
        g->ms_per_mtriangle, g->ms_per_mpixel, g->r2, g->rms_error_ms);
  if (const std::optional<gpu::CostModel>& g = x.run->cost->gpu_sprite)
    say(o, "cost:    CDLOD sprite frame = %.3f ms + %.3f ms/Mtriangle + %.3f ms/Mpixel (r2 %.3f, rms %.3f ms)\n",
        g->base_ms, g->ms_per_mtriangle, g->ms_per_mpixel, g->r2, g->rms_error_ms);
}

// 1. The benchmark harness: every mode interleaved, timed, with bench.json.
void runHarness(Experiment& x) {
  const TerrainBenchOptions& o = x.options;
  const terrain::Heightfield& hf = x.data().hf;
  const size_t full_triangles = size_t(hf.width - 1) * size_t(hf.height - 1) * 2;
  const bool full = full_triangles <= o.full_max_triangles;
  const scene::Scene full_scene = full ? x.data().fullResolutionScene() : scene::Scene();
  if (!full)
    say(o, "note:    the full-resolution grid has %zu triangles (over %zu): the harness's \"full\" baseline draws "
        "nothing\n", full_triangles, o.full_max_triangles);
  BenchOptions options;
  options.modes = o.modes;
  options.width = o.width;
  options.height = o.height;
  options.reference = o.reference;
  options.samples = 4;
  options.out_dir = o.out_dir;
  options.scene_label = o.dem;
  options.path_label = x.result.path_file;
  options.near_plane = x.planes.near_plane;
  options.far_plane = x.planes.far_plane;
  gpu::Context& context = gpu::sharedHeadlessContext();
  say(o, "bench:   %zu frames at %dx%d, modes full (baseline), %s%s\n", x.path.frames.size(), o.width, o.height,
      joined(o.modes).c_str(), o.reference ? ", with full-geometry reference" : "");
  x.result.bench = runBench(context, full_scene, x.path, options);
  context.makeCurrent();
  FF_CHECK(x.result.bench.mode("high") && x.result.bench.mode("low") && x.result.bench.mode("lod-sprite"));
  const std::vector<uint8_t> stalled = stalledFrames(x.result.bench);
  x.result.stalled_frames = size_t(std::accumulate(stalled.begin(), stalled.end(), 0));
  if (x.result.stalled_frames)
    say(o, "note:    %zu frames with stalls left out of the filtered totals\n", x.result.stalled_frames);

  x.result.sprite_log = x.run->logs["lod-sprite"];
  FF_CHECK(x.result.sprite_log.size() == x.result.bench.mode("lod-sprite")->frames.size());
  x.result.keyframes_simulated = terrain::simulateKeyframes(*x.data().lod, x.measuredCameras(), o.low_error, o.epsilon);
}

}  // namespace terrain_experiment

namespace {

using namespace terrain_experiment;

void checkOptions(const TerrainBenchOptions& o) {
  if (o.dem.empty()) throw Error("dem", "a DEM file or fractal:SIZE[:SEED] is required");
  if (o.out_dir.empty()) throw Error("--output", "an output directory is required");
  if (o.width < 1 || o.height < 1) throw Error("--size", "width and height must be positive");
  if (!(o.epsilon > 0.0)) throw Error("--epsilon", "must be positive (pixels)");
  if (!(o.max_magnification == 0.0 || o.max_magnification > 1.0))
    throw Error("--max-magnification", "must be above 1 (0: not bounded)");
  if (!(o.high_error > 0.0f && o.low_error >= o.high_error))
    throw Error("--high-error/--low-error", "need 0 < high <= low (pixels)");
  if (o.quality_stride < 1) throw Error("--quality-stride", "must be at least 1");
  if (o.path.empty() && o.frames < 2) throw Error("--frames", "need at least 2 frames");
  // Frame counts become the flythrough's int (checked here, before anything has run).
  capSize<size_t>(o.frames, size_t(terrain::kMaxFlythroughFrames), "--frames", "frame count");
  for (size_t n : o.sweep_frames)
    capSize<size_t>(n, size_t(terrain::kMaxFlythroughFrames), "--sweep-frames", "frame count");
  for (const char* m : {"high", "low", "lod-sprite"})
    if (std::find(o.modes.begin(), o.modes.end(), m) == o.modes.end())
      throw Error("--modes", std::string("must include ") + m + " (the figures compare high, low and lod-sprite)");
  checkModeNames(o.modes);
  for (double e : o.sweep_epsilons)
    if (!(e > 0.0)) throw Error("--sweep-epsilons", "expected positive numbers, got " + num(e, 3));
  if (o.block < 1) throw Error("--block", "must be at least 1 cell");
  if (o.sprite_tile_cells < 1) throw Error("--sprite-tile-cells", "must be at least 1 cell");
  if (!(o.clearance >= 0.0f)) throw Error("--clearance", "must be 0 (default) or a positive number of metres");
}

}  // namespace

std::string findToolScript(const std::string& name) {
  // __FILE__ is absolute under CMake: src/farfield/eval/ of the source tree this library was built from.
  std::vector<fs::path> candidates{fs::path(__FILE__).parent_path() / ".." / ".." / ".." / "tools" / name};
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    candidates.push_back(exe.parent_path() / ".." / "share" / "farfield" / name);
    candidates.push_back(exe.parent_path() / ".." / ".." / ".." / "tools" / name);  // build/NAME/bin
    candidates.push_back(exe.parent_path() / ".." / ".." / "tools" / name);         // build/bin
  }
  for (const fs::path& c : candidates)
    if (fs::exists(c, ec)) return fs::weakly_canonical(c, ec).string();
  return "";
}

TerrainBenchResult runTerrainBench(const TerrainBenchOptions& options) {
  registerTerrainModes();
  checkOptions(options);

  Stopwatch clock;
  TerrainBenchResult result;
  auto run = std::make_shared<TerrainRun>();
  terrain::TerrainLoadOptions load;
  load.block = options.block;
  run->data = terrain::TerrainData::load(options.dem, load);
  run->high_error = options.high_error;
  run->low_error = options.low_error;
  run->epsilon = options.epsilon;
  run->max_magnification = options.max_magnification;
  run->cost_correction = options.cost_correction;
  run->sprite_tile_cells = options.sprite_tile_cells;
  const ScopedTerrainRun scoped(run);  // the harness's terrain modes draw this terrain
  result.terrain = run->data->describe();
  say(options, "terrain: %s\n", result.terrain.c_str());

  Experiment x{options, result, run, fs::path(options.out_dir), fs::path(options.out_dir) / "figures", {}, false,
               {}, {}};
  fs::create_directories(x.figures / "fig06");
  makePath(x);
  if (options.choice) calibrate(x);
  runHarness(x);
  runQuality(x);
  writePerFrameFigures(x);
  if (options.sweeps) {
    runSweeps(x);
    if (options.section5) runBackAndForth(x);
  }
  writeSummary(x);
  if (options.plots) {
    const std::string script =
        options.terrain_plot_script.empty() ? findToolScript("plot_terrain.py") : options.terrain_plot_script;
    runTerrainPlots(x.figures, script, options.python);
  }
  result.seconds = clock.seconds();
  return result;
}

}  // namespace farfield::eval
