// The LOD-sprite terrain experiment of Chen et al. 1999 (sections 4 and 5, Figures 6 and 8-14): `farfield terrain
// bench`.
//
// Over a camera path (given, or Figure 8's kind of flythrough over the terrain):
// 0. (with choice) the terrain cost model fitted on this machine from a few of the path's frames
//    (terrain/terrain_cost.h), which "lod-sprite" uses to choose per frame between the high LOD and the sprite path;
// 1. the walkthrough benchmark harness (bench.h) runs the modes of terrain_modes.h, interleaved and timed, with the
//    full-resolution mesh as the "full" baseline (bench.json, bench.md, frames.csv, report.md);
// 2. an untimed quality pass: every mode's frame against the high-resolution frame (PSNR), and Figure 6's views;
// 3. Figures 9-11 per frame: triangles, sprite error, frame time;
// 4. sweeps (unless sweeps is false): keyframes against frame count (Figure 12) and threshold (Figure 13) from the
//    render-free simulation of the keyframe decisions, and lod-sprite timed at each threshold against high
//    (Figure 14);
// 5. section 5's variants on a back-and-forth stretch of the path (unless sweeps or section5 is false);
// 6. the summary: terrain.json, terrain.md, and the figures' PNGs drawn by tools/plot_terrain.py (unless plots is
//    false; CSV only when no python with matplotlib is found).
//
// Files under out_dir: path.json (generated paths only), bench.json, bench.md, frames.csv, frames/, report.md,
// terrain.json, terrain.md, and under figures/: fig06/view{1,2}_{a_low,b_high,c_lod_sprite,d_diff_low_high,
// e_diff_high_lod_sprite}.png, fig06_views.csv, fig08_path.csv, fig08_terrain.png, fig09_triangles.csv,
// fig10_error.csv, fig11_time.csv, quality.csv, and with sweeps fig12_keyframes_vs_frames.csv,
// fig13_keyframes_vs_epsilon.csv, fig14_speedup_vs_epsilon.csv, section5_back_and_forth.csv.
//
// What the experiment promises, and the tests check: the lod-sprite mode's keyframes in every timed pass are the
// frames where the render-free simulation of the error metric (terrain::simulateKeyframes) puts them, and its
// frames are closer to the high-resolution frames than the low-resolution frames are (mean PSNR).
#pragma once

#include <cstddef>
#include <cstdio>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "farfield/eval/bench.h"
#include "farfield/eval/frame_stats.h"
#include "farfield/eval/terrain_modes.h"

namespace farfield::eval {

struct TerrainBenchOptions {
  std::string dem;          // a DEM file (terrain/dem_io.h) or fractal:SIZE[:SEED]; required
  std::string path;         // camera path JSON; "" = a flythrough of `frames` frames, saved to out_dir/path.json
  size_t frames = 600;      // frames of the generated flythrough (>= 2)
  float clearance = 0.0f;   // of the generated flythrough: metres above the highest ground near it (0 = its default)
  double epsilon = 1.0;     // LOD-sprite error threshold, pixels (> 0)
  double max_magnification = 0.0;  // LOD-sprite's keyframes also past this sprite magnification (0: equation 2 alone)
  bool cost_correction = true;     // LOD-sprite's choice: its model corrected by the measured frames (false: alone)
  std::string out_dir;      // required
  int width = 512;          // frame size, pixels
  int height = 512;
  float high_error = 1.0f;  // LOD thresholds, pixels: 0 < high_error <= low_error
  float low_error = 4.0f;
  std::vector<std::string> modes{"high",       "high-gpu",          "low",
                                 "lod-sprite", "lod-sprite-gpu",    "lod-sprite-gpu-predict",
                                 "lod-sprite-always", "lod-sprite-predict", "lod-sprite-cache"};
  bool choice = true;       // calibrate the cost model; "lod-sprite" chooses per frame (false: always the sprite)
  bool reference = false;   // also compare every mode with full-geometry frames (the harness)
  // The harness's "full" baseline draws the full-resolution grid; above this many triangles it draws nothing (a
  // 8193 x 8193 grid is 134 M triangles: gigabytes and tens of seconds a frame here), and terrain.md says so.
  size_t full_max_triangles = 8'000'000;
  size_t quality_stride = 1;  // PSNR against high on every K-th measured frame (>= 1)
  std::vector<double> sweep_epsilons{0.25, 0.5, 1, 2, 4, 8};          // Figures 13 and 14 (each > 0)
  std::vector<size_t> sweep_frames{75, 150, 300, 600, 1200, 2400};     // Figure 12 (counts below 2 are skipped)
  bool sweeps = true;       // Figures 12-14 and section 5
  bool section5 = true;     // with sweeps: section 5's variants on the back-and-forth stretch
  bool plots = true;        // false: CSV only
  std::string python;       // interpreter for the plots ("" = python3)
  std::string bench_plot_script;    // tools/plot_bench.py ("" = findToolScript)
  std::string terrain_plot_script;  // tools/plot_terrain.py ("" = findToolScript)
  int block = 128;          // LOD block size, cells
  int sprite_tile_cells = 128;  // tile side of the lod-sprite-tiles mode, cells (>= 1)
  std::FILE* log = stdout;  // what each stage does, one line each; null = quiet
};

// Per measured frame of the quality pass: mode -> PSNR against the high-resolution frame (dB, capped at kPsnrCapDb).
struct TerrainQualityRow {
  size_t path_frame = 0;
  std::map<std::string, double> psnr;       // against the high-resolution LOD's frame ("today's high")
  std::map<std::string, double> psnr_full;  // against the full-resolution grid's frame, where it is drawn; "high" too
};

// Figure 12: lod-sprite keyframes over the path at another frame count (render-free simulation).
struct KeyframesVsFrames {
  size_t frames = 0;
  size_t keyframes = 0;
};

// Figures 13 and 14: lod-sprite at one threshold, timed interleaved with high over the measured frames.
struct EpsilonSweepRow {
  double epsilon_px = 0.0;
  size_t keyframes = 0;            // where the timed pass's error metric tripped (keyframes at trips + virtual ones)
  size_t fresh_keyframes = 0;      // keyframes rendered
  size_t high_frames = 0;          // frames that drew the high LOD (the per-frame choice)
  size_t switches = 0;             // keyframes taken before the metric tripped (terrain/lod_sprite.h)
  size_t keyframes_simulated = 0;  // terrain::simulateKeyframes over the same cameras
  double total_ms = 0.0;           // raw sum of frame times
  double mean_ms = 0.0;            // without stalls (frames over max(1 s, 20x the median))
  double median_ms = 0.0;
  double high_total_ms = 0.0;      // high's mean without stalls x frames
  double speedup_total = 0.0;      // high's mean / mean_ms, both without stalls
  double speedup_median = 0.0;
};

// Section 5 on a back-and-forth stretch: one mode's frame times and keyframe counters.
struct BackAndForthRow {
  std::string mode;
  size_t frames = 0;
  FrameSummary wall;
  double speedup_vs_high_mean = 0.0;
  double high_resolution_renders = 0.0;
  double fresh_keyframes = 0.0;
  double predicted_used = 0.0;
  double cache_hits = 0.0;
};

struct TerrainBenchResult {
  std::string terrain;    // TerrainData::describe()
  std::string path_file;  // the camera path used (out_dir/path.json when generated)
  size_t path_frames = 0;
  BenchResult bench;      // the harness run; each mode's info has speedup_vs_high_* and psnr_vs_high_db_mean
  std::vector<SpriteLog> sprite_log;       // lod-sprite, one per measured frame of the timed pass
  std::vector<uint8_t> keyframes_simulated;  // 1 where terrain::simulateKeyframes puts a keyframe, same frames
  std::optional<terrain::TerrainCost> cost;  // the fitted cost model (with choice)
  size_t stalled_frames = 0;               // left out of the filtered totals
  std::vector<TerrainQualityRow> quality;
  std::map<std::string, double> psnr_mean;  // mode -> mean PSNR against high over `quality`
  std::map<std::string, double> psnr_full_mean;  // mode -> mean PSNR against full resolution (empty: not drawn)
  std::vector<KeyframesVsFrames> keyframes_vs_frames;  // empty without sweeps
  std::vector<EpsilonSweepRow> epsilon_sweep;          // empty without sweeps
  std::vector<BackAndForthRow> back_and_forth;         // empty without sweeps
  std::string markdown;   // terrain.md
  double seconds = 0.0;   // wall time of the whole experiment
};

// Runs the experiment and writes its files (see the top of this file). Needs no current context (uses the shared
// headless one). Throws farfield::Error naming the option (as the command line spells it: "--epsilon", "--modes",
// ...) for bad options, before loading or writing anything; and for a bad DEM or path file.
TerrainBenchResult runTerrainBench(const TerrainBenchOptions& options);

// A script of tools/ (plot_bench.py, plot_terrain.py): in the source tree this library was built from, else next to
// an installed or build-tree executable; "" when not found.
std::string findToolScript(const std::string& name);

}  // namespace farfield::eval
