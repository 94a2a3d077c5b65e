// The terrain experiment's sweeps (Figures 12-14) and section 5's variants on a back-and-forth stretch.
#include "farfield/eval/terrain_experiment.h"

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

namespace farfield::eval::terrain_experiment {

// A renderer, a target and the harness's frame runner, with a mode context for them: the timed loops below.
struct TimedLoop {
  gpu::Renderer renderer;
  gpu::RenderTarget target;
  FrameRunner runner;
  ModeContext context;
  TimedLoop(int width, int height) : target(width, height), runner(renderer, target) {
    context.renderer = &renderer;
    context.width = width;
    context.height = height;
  }
};

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
  TimedLoop loop(o.width, o.height);
  FrameRunner& runner = loop.runner;
  const ModeContext& mc = loop.context;
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
  TimedLoop loop(o.width, o.height);
  FrameRunner& runner = loop.runner;
  const ModeContext& mc = loop.context;
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

}  // namespace farfield::eval::terrain_experiment
