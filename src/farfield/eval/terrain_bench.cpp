// The LOD-sprite terrain experiment, Chen et al. 1999 sections 4 and 5 (Figures 6 and 8-14).
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

namespace fs = std::filesystem;

namespace farfield::eval {
namespace {

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
std::string num(double v, int decimals = 4) {
  if (!std::isfinite(v)) return "";
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f", decimals, v);
  return buf;
}

template <class T>
std::string joined(const std::vector<T>& values) {
  std::ostringstream out;
  for (size_t i = 0; i < values.size(); ++i) out << (i ? "," : "") << values[i];
  return out.str();
}

// Absolute difference |a - b| per channel, scaled by `gain` (the paper's Figure 6d/e difference images).
image::ColorImage absDifference(const image::ColorImage& a, const image::ColorImage& b, int gain = 4) {
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

void checkOptions(const TerrainBenchOptions& o) {
  if (o.dem.empty()) throw Error("dem", "a DEM file or fractal:SIZE[:SEED] is required");
  if (o.out_dir.empty()) throw Error("--output", "an output directory is required");
  if (o.width < 1 || o.height < 1) throw Error("--size", "width and height must be positive");
  if (!(o.epsilon > 0.0)) throw Error("--epsilon", "must be positive (pixels)");
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

// Everything the stages share.
struct Experiment {
  const TerrainBenchOptions& options;
  TerrainBenchResult& result;
  std::shared_ptr<TerrainRun> run;
  fs::path out, figures;
  gen::CameraPath path;
  bool generated = false;
  terrain::FlythroughOptions fly;
  ClipPlanes planes;

  const terrain::TerrainData& data() const { return *run->data; }
  Camera cameraAt(const gen::CameraPath& p, size_t i) const {
    return pathCamera(p, i, options.width, options.height, planes.near_plane, planes.far_plane);
  }
  std::vector<Camera> measuredCameras() const {
    std::vector<Camera> cameras;
    for (size_t i : result.bench.frame_indices) cameras.push_back(cameraAt(path, i));
    return cameras;
  }
};

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

// 0. The cost model of this machine's terrain frames, from 5 frames spread over the path (untimed, before the
// harness), for lod-sprite's per-frame choice.
void calibrate(Experiment& x) {
  const TerrainBenchOptions& o = x.options;
  gpu::sharedHeadlessContext().makeCurrent();
  std::vector<Camera> views;
  const size_t n = x.path.frames.size();
  for (size_t k = 0; k < 5; ++k) views.push_back(x.cameraAt(x.path, std::min(n - 1, (2 * k + 1) * n / 10)));
  const bool gpu_sprite = std::find(o.modes.begin(), o.modes.end(), "lod-sprite-gpu") != o.modes.end();
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

// 2. Quality pass (untimed): every mode's frame against the high-resolution frame, and Figure 6's views.
void runQuality(Experiment& x) {
  const TerrainBenchOptions& o = x.options;
  const BenchResult& bench = x.result.bench;
  const terrain::TerrainData& data = x.data();
  say(o, "quality: frames against high resolution (every %zu)\n", o.quality_stride);
  gpu::TerrainRenderer& renderer = x.run->gpuRenderer();
  gpu::RenderTarget target(o.width, o.height);
  std::vector<std::pair<std::string, std::unique_ptr<terrain::LodSpriteRenderer>>> sprites;
  for (const std::string& name : o.modes) {
    SpriteVariant variant;
    bool gpu_high = false;
    if (!spriteVariantOf(name, variant, &gpu_high)) continue;
    sprites.emplace_back(name, std::make_unique<terrain::LodSpriteRenderer>(
                                   *data.lod, renderer, o.width, o.height,
                                   spriteOptions(*x.run, variant, o.epsilon, gpu_high ? &x.run->gpuLod() : nullptr)));
  }
  std::vector<std::pair<std::string, std::unique_ptr<terrain::TileSpriteRenderer>>> tiles;
  for (const std::string& name : o.modes) {
    if (isTileSpriteMode(name))
      tiles.emplace_back(name, std::make_unique<terrain::TileSpriteRenderer>(*data.lod, renderer, o.width, o.height,
                                                                             tileSpriteOptions(*x.run, name)));
  }
  // Figure 6 and 7's views: over the plain (40% of the path) and over the mountains (70%).
  const std::set<size_t> views{bench.frame_indices[bench.frame_indices.size() * 2 / 5],
                               bench.frame_indices[bench.frame_indices.size() * 7 / 10]};
  std::ostringstream views_csv;
  views_csv << "view,path_frame,high_triangles,low_triangles,lod_sprite_triangles,psnr_low_vs_high_db,"
               "psnr_lod_sprite_vs_high_db,mae_low,mae_lod_sprite\n";
  int view_number = 0;
  terrain::LodMesh mesh;
  Progress progress("quality", bench.frame_indices.size());
  for (size_t k = 0; k < bench.frame_indices.size(); ++k) {
    const size_t pf = bench.frame_indices[k];
    const Camera camera = x.cameraAt(x.path, pf);
    const bool measure = k % o.quality_stride == 0 || views.count(pf);
    TerrainQualityRow row;
    row.path_frame = pf;
    image::ColorImage high_image, low_image;
    uint64_t high_tris = 0, low_tris = 0;
    if (measure) {
      target.clear(x.run->sky);
      high_tris = terrain::renderLodFrame(*data.lod, renderer, camera, {o.high_error, true, false}, target, mesh)
                      .triangles;
      high_image = target.readColor();
      target.clear(x.run->sky);
      low_tris = terrain::renderLodFrame(*data.lod, renderer, camera, {o.low_error, true, false}, target, mesh)
                     .triangles;
      low_image = target.readColor();
      row.psnr["low"] = std::min(image::psnr(high_image, low_image), kPsnrCapDb);
    }
    for (auto& [name, s] : sprites) {
      target.clear(x.run->sky);
      terrain::LodSpriteFrameInfo info;
      s->render(camera, target, &info);
      if (!measure) continue;
      const image::ColorImage img = target.readColor();
      row.psnr[name] = std::min(image::psnr(high_image, img), kPsnrCapDb);
      if (name == "lod-sprite" && views.count(pf)) {
        ++view_number;
        const std::string tag = "view" + std::to_string(view_number);
        const fs::path dir = x.figures / "fig06";
        image::writePng((dir / (tag + "_a_low.png")).string(), low_image);
        image::writePng((dir / (tag + "_b_high.png")).string(), high_image);
        image::writePng((dir / (tag + "_c_lod_sprite.png")).string(), img);
        image::writePng((dir / (tag + "_d_diff_low_high.png")).string(), absDifference(low_image, high_image));
        image::writePng((dir / (tag + "_e_diff_high_lod_sprite.png")).string(), absDifference(high_image, img));
        views_csv << view_number << "," << pf << "," << high_tris << "," << low_tris << ","
                  << info.low_triangles + info.keyframe_triangles << "," << num(row.psnr["low"], 3) << ","
                  << num(row.psnr[name], 3) << "," << num(image::meanAbsoluteError(high_image, low_image), 3) << ","
                  << num(image::meanAbsoluteError(high_image, img), 3) << "\n";
      }
    }
    for (auto& [name, t] : tiles) {
      target.clear(x.run->sky);
      t->render(camera, target);
      if (!measure) continue;
      const image::ColorImage img = target.readColor();
      row.psnr[name] = std::min(image::psnr(high_image, img), kPsnrCapDb);
      if (views.count(pf)) {  // Figure 6's views for the tile modes too, next to lod-sprite's
        const std::string tag = "view" + std::to_string(1 + std::distance(views.begin(), views.find(pf)));
        const fs::path dir = x.figures / "fig06";
        image::writePng((dir / (tag + "_f_" + name + ".png")).string(), img);
        image::writePng((dir / (tag + "_g_diff_high_" + name + ".png")).string(), absDifference(high_image, img));
      }
    }
    for (const std::string& name : o.modes) {  // the CDLOD terrain on the GPU at each threshold
      if (!measure || (name != "high-gpu" && name != "low-gpu")) continue;
      target.clear(x.run->sky);
      x.run->gpuLod().draw(camera, name == "high-gpu" ? o.high_error : o.low_error, target);
      const image::ColorImage img = target.readColor();
      row.psnr[name] = std::min(image::psnr(high_image, img), kPsnrCapDb);
      if (views.count(pf)) {
        const std::string tag = "view" + std::to_string(1 + std::distance(views.begin(), views.find(pf)));
        const fs::path dir = x.figures / "fig06";
        image::writePng((dir / (tag + "_f_" + name + ".png")).string(), img);
        image::writePng((dir / (tag + "_g_diff_high_" + name + ".png")).string(), absDifference(high_image, img));
      }
    }
    if (measure) x.result.quality.push_back(std::move(row));
    progress.advance();
  }
  progress.finish();
  writeText(x.figures / "fig06_views.csv", views_csv.str());
  for (const TerrainQualityRow& row : x.result.quality)
    for (const auto& [name, v] : row.psnr) x.result.psnr_mean[name] += v / double(x.result.quality.size());

  std::ostringstream q;
  q << "path_frame";
  std::vector<std::string> qnames;
  if (!x.result.quality.empty())
    for (const auto& [name, v] : x.result.quality.front().psnr) qnames.push_back(name);
  for (const std::string& n : qnames) q << ",psnr_" << n << "_vs_high_db";
  q << "\n";
  for (const TerrainQualityRow& row : x.result.quality) {
    q << row.path_frame;
    for (const std::string& n : qnames) q << "," << num(row.psnr.at(n), 3);
    q << "\n";
  }
  writeText(x.figures / "quality.csv", q.str());
}

// 3. Figures 9-11: per-frame triangles, error, time (from the harness's records and the sprite mode's log).
void writePerFrameFigures(const Experiment& x) {
  const BenchResult& bench = x.result.bench;
  const ModeResult& high = *bench.mode("high");
  const ModeResult& low = *bench.mode("low");
  const ModeResult& sprite = *bench.mode("lod-sprite");
  const std::vector<SpriteLog>& log = x.result.sprite_log;
  std::ostringstream f9, f10, f11;
  f9 << "frame,path_frame,high,low,lod_sprite,keyframe\n";
  f10 << "frame,path_frame,error_px,trigger_error_px,keyframe,source,path,keyframe_due,predicted_high_ms,"
         "predicted_sprite_ms,predicted_keyframe_ms,expected_lifetime,switched\n";
  f11 << "frame,path_frame";
  for (const ModeResult& m : bench.modes) f11 << "," << m.name << "_ms";
  f11 << ",lod_sprite_keyframe,lod_sprite_path\n";
  for (size_t k = 0; k < bench.frame_indices.size(); ++k) {
    const bool key = log[k].info.source == terrain::SpriteSource::Fresh;
    f9 << k << "," << bench.frame_indices[k] << "," << high.frames[k].triangles << "," << low.frames[k].triangles
       << "," << sprite.frames[k].triangles << "," << key << "\n";
    f10 << k << "," << bench.frame_indices[k] << "," << num(log[k].info.error_px) << ","
        << num(log[k].info.trigger_error_px) << "," << key << "," << terrain::spriteSourceName(log[k].info.source)
        << "," << terrain::terrainPathName(log[k].info.path) << "," << log[k].info.keyframe_due << ","
        << num(log[k].info.predicted_high_ms, 3) << "," << num(log[k].info.predicted_sprite_ms, 3) << ","
        << num(log[k].info.predicted_keyframe_ms, 3) << "," << num(log[k].info.expected_lifetime, 1) << ","
        << log[k].info.switched << "\n";
    f11 << k << "," << bench.frame_indices[k];
    for (const ModeResult& m : bench.modes) f11 << "," << num(m.frames[k].wall_ms, 3);
    f11 << "," << key << "," << terrain::terrainPathName(log[k].info.path) << "\n";
  }
  writeText(x.figures / "fig09_triangles.csv", f9.str());
  writeText(x.figures / "fig10_error.csv", f10.str());
  writeText(x.figures / "fig11_time.csv", f11.str());
}

// 4. Sweeps. Figures 12 and 13 (keyframe fraction against frame count and threshold) from the keyframe decisions
// alone (no rendering needed: they depend on the viewpoints and the low-resolution meshes only); Figure 14
// (speedup against threshold) timed: lod-sprite at each threshold over the same frames, interleaved, against
// high-resolution frames in the same loop.
void runSweeps(Experiment& x) {
  const TerrainBenchOptions& o = x.options;
  const terrain::TerrainData& data = x.data();
  say(o, "sweeps:  keyframes against frame count %s and threshold %s\n", joined(o.sweep_frames).c_str(),
      joined(o.sweep_epsilons).c_str());
  std::ostringstream f12;
  f12 << "frames,keyframes,keyframe_fraction\n";
  for (size_t n : o.sweep_frames) {
    if (n < 2) continue;
    gen::CameraPath p;
    if (x.generated) {
      terrain::FlythroughOptions fly = x.fly;
      fly.frames = checkedCast<int>(n, "--sweep-frames", "frame count");
      p = flythroughCameraPath(data.hf, fly);
    } else {
      p = resampleCameraPath(x.path, n);
    }
    std::vector<Camera> cameras;
    for (size_t i = 0; i < p.frames.size(); ++i) cameras.push_back(x.cameraAt(p, i));
    const auto keys = terrain::simulateKeyframes(*data.lod, cameras, o.low_error, o.epsilon);
    const size_t count = size_t(std::accumulate(keys.begin(), keys.end(), 0));
    f12 << n << "," << count << "," << num(double(count) / double(n), 5) << "\n";
    x.result.keyframes_vs_frames.push_back({n, count});
  }
  writeText(x.figures / "fig12_keyframes_vs_frames.csv", f12.str());

  const std::vector<Camera> cameras = x.measuredCameras();
  const std::vector<size_t>& indices = x.result.bench.frame_indices;
  // Timed sweep with the harness's frame runner and its frame-time definition.
  gpu::Renderer renderer;
  gpu::RenderTarget target(o.width, o.height);
  FrameRunner runner(renderer, target);
  ModeContext mc;
  mc.renderer = &renderer;
  mc.width = o.width;
  mc.height = o.height;
  // High resolution runs in the same interleaved loop, so that every ratio is measured over the same minutes (the
  // load of a shared machine drifts between the harness run and this one).
  std::vector<std::unique_ptr<SpriteMode>> modes;
  for (double e : o.sweep_epsilons) {
    modes.push_back(std::make_unique<SpriteMode>("lod-sprite@" + num(e, 2), SpriteVariant::Paper, e));
    modes.back()->prepare(mc);
  }
  LodMode sweep_high("high", true);
  sweep_high.prepare(mc);
  std::vector<double> totals(modes.size(), 0.0);
  std::vector<std::vector<double>> times(modes.size(), std::vector<double>());
  std::vector<double> high_times;
  high_times.reserve(cameras.size());
  for (auto& t : times) t.reserve(cameras.size());
  Progress progress("epsilon sweep", cameras.size() * (modes.size() + 1));
  for (size_t k = 0; k < cameras.size(); ++k)
    for (size_t j = 0; j <= modes.size(); ++j) {
      const size_t m = (k + j) % (modes.size() + 1);
      if (m == modes.size()) {
        high_times.push_back(runner.run(sweep_high, cameras[k], indices[k]).wall_ms);
      } else {
        const FrameRecord r = runner.run(*modes[m], cameras[k], indices[k]);
        totals[m] += r.wall_ms;
        times[m].push_back(r.wall_ms);
      }
      progress.advance();
    }
  progress.finish();
  const FrameSummary high_summary = summarize(high_times);
  const double high_mean = meanWithoutStalls(high_times, high_summary.median);
  std::ostringstream f13, f14;
  f13 << "epsilon_px,keyframes,keyframe_fraction,keyframes_simulated,fresh_keyframes,high_frames,switches\n";
  // Speedup = mean frame time of high / mean frame time of lod-sprite at the threshold, both from this sweep and
  // without stalls; total_ms is the raw sum.
  f14 << "epsilon_px,total_ms,mean_ms,median_ms,high_total_ms,speedup_total,speedup_median\n";
  for (size_t m = 0; m < modes.size(); ++m) {
    EpsilonSweepRow row;
    row.epsilon_px = o.sweep_epsilons[m];
    const terrain::LodSpriteCounters& counters = modes[m]->sprite().counters();
    row.keyframes = counters.fresh_keyframes - counters.switches + counters.virtual_keyframes;
    row.switches = counters.switches;
    row.fresh_keyframes = counters.fresh_keyframes;
    row.high_frames = counters.high_frames;
    const auto sim = terrain::simulateKeyframes(*data.lod, cameras, o.low_error, row.epsilon_px);
    row.keyframes_simulated = size_t(std::accumulate(sim.begin(), sim.end(), 0));
    const FrameSummary s = summarize(times[m]);
    row.total_ms = totals[m];
    row.mean_ms = meanWithoutStalls(times[m], s.median);
    row.median_ms = s.median;
    row.high_total_ms = high_mean * double(times[m].size());
    row.speedup_total = high_mean / row.mean_ms;
    row.speedup_median = high_summary.median / s.median;
    f13 << num(row.epsilon_px, 3) << "," << row.keyframes << ","
        << num(double(row.keyframes) / double(cameras.size()), 5) << "," << row.keyframes_simulated << ","
        << row.fresh_keyframes << "," << row.high_frames << "," << row.switches << "\n";
    f14 << num(row.epsilon_px, 3) << "," << num(row.total_ms, 2) << "," << num(row.mean_ms, 3) << ","
        << num(row.median_ms, 3) << "," << num(row.high_total_ms, 2) << "," << num(row.speedup_total, 3) << ","
        << num(row.speedup_median, 3) << "\n";
    x.result.epsilon_sweep.push_back(row);
  }
  writeText(x.figures / "fig13_keyframes_vs_epsilon.csv", f13.str());
  writeText(x.figures / "fig14_speedup_vs_epsilon.csv", f14.str());
}

// 5. Section 5's keyframe cache where it can help: the viewer moving back and forth over one stretch of the path
// (forwards, then the same frames backwards, twice), lod-sprite and its variants timed, interleaved.
void runBackAndForth(Experiment& x) {
  const TerrainBenchOptions& o = x.options;
  const size_t n = x.path.frames.size();
  const size_t first = n / 2, length = std::max<size_t>(2, std::min<size_t>(120, n / 4));
  std::vector<terrain::Viewpoint> viewpoints;
  for (const gen::PathFrame& f : x.path.frames) viewpoints.push_back({f.eye, f.at, f.fov_y});
  const gen::CameraPath bf =
      terrainCameraPath(terrain::backAndForth(viewpoints, std::min(first, n - length), length, 2), "back-and-forth");
  say(o, "section 5: back and forth over path frames %zu..%zu (%zu frames)\n", std::min(first, n - length),
      std::min(first, n - length) + length - 1, bf.frames.size());
  gpu::Renderer renderer;
  gpu::RenderTarget target(o.width, o.height);
  FrameRunner runner(renderer, target);
  ModeContext mc;
  mc.renderer = &renderer;
  mc.width = o.width;
  mc.height = o.height;
  std::vector<std::unique_ptr<Mode>> modes;
  modes.push_back(std::make_unique<LodMode>("high", true));
  modes.push_back(std::make_unique<SpriteMode>("lod-sprite", SpriteVariant::Paper));
  modes.push_back(std::make_unique<SpriteMode>("lod-sprite-predict", SpriteVariant::Predict));
  modes.push_back(std::make_unique<SpriteMode>("lod-sprite-cache", SpriteVariant::Cache));
  for (auto& m : modes) m->prepare(mc);
  std::vector<std::vector<double>> times(modes.size());
  for (size_t k = 0; k < bf.frames.size(); ++k) {
    const Camera camera = x.cameraAt(bf, k);
    for (size_t j = 0; j < modes.size(); ++j) {
      const size_t m = (k + j) % modes.size();
      times[m].push_back(runner.run(*modes[m], camera, k).wall_ms);
    }
  }
  std::ostringstream csv;
  csv << "mode,frames,mean_ms,median_ms,p99_ms,max_ms,speedup_vs_high_mean,high_resolution_renders,"
         "fresh_keyframes,predicted_used,cache_hits\n";
  const double high_mean = summarize(times[0]).mean;
  for (size_t m = 0; m < modes.size(); ++m) {
    const auto info = modes[m]->info();
    auto get = [&](const char* key) { auto it = info.find(key); return it == info.end() ? 0.0 : it->second; };
    BackAndForthRow row;
    row.mode = modes[m]->name();
    row.frames = bf.frames.size();
    row.wall = summarize(times[m]);
    row.speedup_vs_high_mean = high_mean / row.wall.mean;
    row.high_resolution_renders = get("high_resolution_renders");
    row.fresh_keyframes = get("keyframes");
    row.predicted_used = get("predicted_used");
    row.cache_hits = get("cache_hits");
    csv << row.mode << "," << row.frames << "," << num(row.wall.mean, 3) << "," << num(row.wall.median, 3) << ","
        << num(row.wall.p99, 3) << "," << num(row.wall.max, 3) << "," << num(row.speedup_vs_high_mean, 3) << ","
        << num(row.high_resolution_renders, 0) << "," << num(row.fresh_keyframes, 0) << ","
        << num(row.predicted_used, 0) << "," << num(row.cache_hits, 0) << "\n";
    x.result.back_and_forth.push_back(row);
  }
  writeText(x.figures / "section5_back_and_forth.csv", csv.str());
}

// 6. Summary: bench.json gets the terrain numbers under each mode's info; terrain.json / terrain.md the headline.
void writeSummary(Experiment& x) {
  const TerrainBenchOptions& o = x.options;
  TerrainBenchResult& r = x.result;
  BenchResult& bench = r.bench;
  const std::vector<uint8_t> stalled = stalledFrames(bench);
  const ModeResult high = *bench.mode("high");
  const double high_total = totalMs(high);
  const double high_filtered = filteredMs(high, stalled);
  for (ModeResult& m : bench.modes) {
    const double t = totalMs(m);
    if (t > 0.0) m.info["speedup_vs_high_total"] = high_total / t;
    if (filteredMs(m, stalled) > 0.0) m.info["speedup_vs_high_filtered_total"] = high_filtered / filteredMs(m, stalled);
    if (high.wall.median > 0.0) m.info["speedup_vs_high_median"] = high.wall.median / m.wall.median;
    if (r.psnr_mean.count(m.name)) m.info["psnr_vs_high_db_mean"] = r.psnr_mean[m.name];
  }
  if (o.plots) {
    writeBenchOutputs(bench, o.out_dir);
    const std::string script = o.bench_plot_script.empty() ? findToolScript("plot_bench.py") : o.bench_plot_script;
    bench.plots = runPlotScript(o.out_dir, script, o.python);
  }
  writeBenchOutputs(bench, o.out_dir);
  writeReport(bench, o.out_dir, (x.out / "report.md").string());

  nlohmann::ordered_json sweep_json;
  if (o.sweeps) {
    for (const KeyframesVsFrames& k : r.keyframes_vs_frames)
      sweep_json["keyframes_vs_frames"].push_back({{"frames", k.frames}, {"keyframes", k.keyframes}});
    for (const EpsilonSweepRow& e : r.epsilon_sweep)
      sweep_json["epsilon"].push_back({{"epsilon_px", e.epsilon_px},
                                       {"keyframes", e.keyframes},
                                       {"keyframes_simulated", e.keyframes_simulated},
                                       {"fresh_keyframes", e.fresh_keyframes},
                                       {"high_frames", e.high_frames},
                                       {"switches", e.switches},
                                       {"total_ms", e.total_ms},
                                       {"mean_ms_without_stalls", e.mean_ms},
                                       {"speedup_total", e.speedup_total}});
  }
  nlohmann::ordered_json section5;
  for (const BackAndForthRow& b : r.back_and_forth)
    section5[b.mode] = {{"mean_ms", b.wall.mean},
                        {"p99_ms", b.wall.p99},
                        {"max_ms", b.wall.max},
                        {"speedup_vs_high_mean", b.speedup_vs_high_mean},
                        {"high_resolution_renders", b.high_resolution_renders},
                        {"fresh_keyframes", b.fresh_keyframes},
                        {"predicted_used", b.predicted_used},
                        {"cache_hits", b.cache_hits}};

  nlohmann::ordered_json summary;
  summary["terrain"] = r.terrain;
  summary["frames"] = bench.frame_indices.size();
  summary["size"] = {o.width, o.height};
  summary["renderer"] = bench.renderer;
  summary["epsilon_px"] = o.epsilon;
  summary["high_error_px"] = o.high_error;
  summary["low_error_px"] = o.low_error;
  summary["paper_speedup_at_1px"] = 9.9;
  summary["quality_stride"] = o.quality_stride;
  summary["stalled_frames_filtered"] = r.stalled_frames;
  const size_t full_triangles = size_t(x.data().hf.width - 1) * size_t(x.data().hf.height - 1) * 2;
  summary["full_baseline_drawn"] = full_triangles <= o.full_max_triangles;
  if (r.cost) {
    // How well the cost model predicted this run: measured / predicted per frame, for the high mode's frames (against
    // lod-sprite's prediction of the high LOD at the same frame) and for lod-sprite's kept-sprite frames.
    const ModeResult* sprite = bench.mode("lod-sprite");
    std::vector<double> high_ratio, sprite_ratio;
    for (size_t k = 0; sprite && k < r.sprite_log.size() && k < high.frames.size(); ++k) {
      const terrain::LodSpriteFrameInfo& info = r.sprite_log[k].info;
      if (info.predicted_high_ms > 0.0) high_ratio.push_back(high.frames[k].wall_ms / info.predicted_high_ms);
      if (info.source == terrain::SpriteSource::Kept && info.predicted_sprite_ms > 0.0)
        sprite_ratio.push_back(sprite->frames[k].wall_ms / info.predicted_sprite_ms);
    }
    nlohmann::ordered_json check;
    for (const auto& [name, v] : {std::pair{"high", &high_ratio}, std::pair{"sprite_kept", &sprite_ratio}})
      if (!v->empty()) {
        const FrameSummary s = summarize(*v);
        check[name] = {{"frames", v->size()}, {"median", s.median}, {"p95", s.p95}};
      }
    summary["cost_model"] = r.cost->toJson();
    summary["cost_model"]["measured_over_predicted"] = check;
  }
  std::ostringstream md;
  md << "# LOD-sprite terrain benchmark\n\n- terrain: " << r.terrain << "\n- " << bench.frame_indices.size()
     << " frames at " << o.width << "x" << o.height << ", epsilon " << o.epsilon << " px, LOD thresholds high "
     << o.high_error << " px / low " << o.low_error << " px\n- renderer: " << bench.renderer
     << "\n- speedup = total time of high / total time of the mode over the path (the paper's 316 s / 32 s = 9.9x), "
        "over the frames without stalls (" << r.stalled_frames << " of " << bench.frame_indices.size()
     << " frames left out: some mode took over max(1 s, 20x its median) there); raw total and median ratios in "
        "brackets; PSNR against the high-resolution frame (untimed quality pass)\n"
     << (full_triangles <= o.full_max_triangles ? ""
                                                : "- full: NOT drawn (the full-resolution grid is over the triangle "
                                                  "cap); its row times an empty frame\n")
     << "\n"
     << "| mode | mean ms | median ms | p99 ms | max ms | triangles | speedup vs high (raw, median) | "
        "PSNR vs high dB | high-res renders | keyframe fraction | high-LOD frames |\n"
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const ModeResult& m : bench.modes) {
    const double t = totalMs(m);
    const double filtered = filteredMs(m, stalled);
    nlohmann::ordered_json e;
    e["mean_ms"] = m.wall.mean;
    e["median_ms"] = m.wall.median;
    e["p99_ms"] = m.wall.p99;
    e["max_ms"] = m.wall.max;
    e["total_ms"] = t;
    e["mean_triangles"] = m.mean_triangles;
    e["speedup_vs_high_total"] = high_total / t;
    e["filtered_total_ms"] = filtered;
    e["speedup_vs_high_filtered_total"] = high_filtered / filtered;
    e["speedup_vs_high_median"] = high.wall.median / m.wall.median;
    if (r.psnr_mean.count(m.name)) e["psnr_vs_high_db_mean"] = r.psnr_mean[m.name];
    for (const auto& [k, v] : m.info) e["info"][k] = v;
    summary["modes"][m.name] = e;
    const auto info = [&](const char* key) {
      auto it = m.info.find(key);
      return it == m.info.end() ? -1.0 : it->second;
    };
    md << "| " << m.name << " | " << num(m.wall.mean, 2) << " | " << num(m.wall.median, 2) << " | "
       << num(m.wall.p99, 2) << " | " << num(m.wall.max, 2) << " | " << num(m.mean_triangles, 0) << " | "
       << num(high_filtered / filtered, 2) << "x (" << num(high_total / t, 2) << "x, "
       << num(high.wall.median / m.wall.median, 2) << "x) | "
       << (r.psnr_mean.count(m.name) ? num(r.psnr_mean[m.name], 2)
                                     : std::string(m.name == "high" ? "(reference)" : "n/a"))
       << " | " << (info("high_resolution_renders") >= 0 ? num(info("high_resolution_renders"), 0) : "") << " | "
       << (info("keyframe_fraction") >= 0 ? num(info("keyframe_fraction"), 4) : "") << " | "
       << (info("high_frames") >= 0 ? num(info("high_frames"), 0) : "") << " |\n";
  }
  if (r.cost) {
    const gpu::CostModel& c = r.cost->frame;
    md << "\nCost model (fitted at the start of the run, for lod-sprite's per-frame choice): " << num(c.base_ms, 3)
       << " ms + " << num(c.ms_per_mtriangle, 1) << " ms/Mtriangle + " << num(c.ms_per_draw, 3) << " ms/draw + "
       << num(c.ms_per_mpixel, 2) << " ms/Mpixel (r2 " << num(c.r2, 3) << "), z-buffer read back "
       << num(r.cost->readback_ms_per_mpixel, 3) << " ms/Mpixel";
    if (const std::optional<gpu::CostModel>& g = r.cost->gpu_high)
      md << "; CDLOD frames (lod-sprite-gpu's high frames and keyframes): " << num(g->base_ms, 3) << " ms + "
         << num(g->ms_per_mtriangle, 1) << " ms/Mtriangle + " << num(g->ms_per_mpixel, 2) << " ms/Mpixel (r2 "
         << num(g->r2, 3) << ")";
    const auto& check = summary["cost_model"]["measured_over_predicted"];
    for (const char* k : {"high", "sprite_kept"})
      if (check.contains(k))
        md << "; measured / predicted " << k << " frames: median " << num(check[k]["median"].get<double>(), 2)
           << ", p95 " << num(check[k]["p95"].get<double>(), 2);
    md << ".\n";
  }
  summary["sweeps"] = sweep_json;
  summary["section5_back_and_forth"] = section5;
  writeText(x.out / "terrain.json", summary.dump(2) + "\n");
  md << "\nFigures (CSV next to each PNG) in figures/: fig06 views, fig08 path, fig09 triangles, fig10 error, fig11 "
        "time, fig12 keyframe fraction vs frames, fig13 vs epsilon, fig14 speedup vs epsilon; "
        "section5_back_and_forth.csv: the variants on a back-and-forth stretch of the path.\n";
  if (!section5.empty()) {
    md << "\nSection 5 on a back-and-forth stretch (forwards, backwards, twice):\n\n"
          "| mode | mean ms | p99 ms | max ms | speedup vs high (mean) | high-res renders | fresh keyframes | "
          "predicted used | cache hits |\n"
          "|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    for (const BackAndForthRow& b : r.back_and_forth)
      md << "| " << b.mode << " | " << num(b.wall.mean, 2) << " | " << num(b.wall.p99, 2) << " | "
         << num(b.wall.max, 2) << " | " << num(b.speedup_vs_high_mean, 2) << "x | "
         << num(b.high_resolution_renders, 0) << " | " << num(b.fresh_keyframes, 0) << " | "
         << num(b.predicted_used, 0) << " | " << num(b.cache_hits, 0) << " |\n";
  }
  r.markdown = md.str();
  writeText(x.out / "terrain.md", r.markdown);
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
