// `farfield bench`: the walkthrough benchmark. Every mode runs over the same camera-path frames in one process,
// interleaved (for each frame every mode in turn, the order rotated by one each frame) so that machine drift (clock
// boost, thermal state, other processes) hits all modes alike. Each mode renders one untimed warm-up frame first.
// With a reference, every frame is also rendered from full geometry (untimed) and each mode's frame is compared
// with it (image::compareImages: PSNR, SSIM, share of pixels off by more than 8/255).
//
// Outputs (writeBenchOutputs): OUTDIR/bench.json, OUTDIR/bench.md, OUTDIR/frames.csv, sample frames under
// OUTDIR/frames/; plots come from tools/plot_bench.py (runPlotScript) and a report from writeReport().
//
// bench.json (later modes add their own entries under "modes"; readers must ignore keys they do not know):
//   {"scene": "...", "path": "...", "path_frames": P, "frames": N, "size": [w, h], "renderer": "...",
//    "date": "2024-01-31T12:00:00Z", "machine": {"hostname", "os", "cpu", "logical_cores"},
//    "baseline": "full", "baseline_added": bool, "reference": bool, "warmup_frames_per_mode": 1,
//    "percentiles": "linear interpolation between closest ranks", "psnr_cap_db": 99,
//    "modes": {"full": {"median_ms", "p95_ms", "p99_ms", "max_ms", "mean_ms", "gpu_median_ms", "gpu_p95_ms",
//                       "cpu_median_ms", "cpu_p95_ms", "cpu_max_ms", "driver_median_ms", "mean_gl_calls",
//                       "max_gl_calls", "max_draw_calls", "mean_dispatches", "mean_upload_bytes", "max_upload_bytes",
//                       "mean_syncs", "max_syncs", "frames_with_syncs" (null where GL calls were not counted),
//                       "mean_triangles", "mean_draw_calls", "mean_objects", "speedup_vs_full",
//                       "psnr_db_mean", "psnr_db_min", "ssim_mean", "bad_pixel_share_mean", "crack_share_mean",
//                       "parallax_p99_px_mean", "parallax_p99_px_max", "error_bound_px", "error_bound_source",
//                       "frames_over_bound", "frames_checked_against_bound", "popping_mean", "popping_p99",
//                       "popping_max", "info": {...}}, ...},
//    "allocator": {"applied": bool, "description": "..."}}
// Governed modes add "frames_relaxed" and "bound_scale_max" (null for other modes); bench.md lists them below the table.
// speedup_vs_full = median_ms(full) / median_ms(mode). PSNR of identical frames is infinite; it is stored capped at
// kPsnrCapDb (per frame, before the mean and min). Without a reference the error keys are null.
//
// The error bound (DESIGN.md, "the two promises"): with a reference, a frame of a mode is *over the bound* when its
// parallax error (99th percentile, pixels) exceeds the bound: BenchOptions::error_px when given (`--error-px`), else
// the mode's info()["error_bound_px"] (the impostor modes report their database's bound), else there is none
// ("error_bound_px": null, frames.csv shows "-"). Frames whose parallax cannot be measured are not checked
// ("frames_checked_against_bound" counts those that were). Popping (eval/temporal_error.h) is the mode's image change
// between consecutive measured frames beyond the reference's, in 8-bit units.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "farfield/core/allocator.h"  // BenchResult reports the allocator; timed commands configure it first
#include "farfield/eval/frame_runner.h"
#include "farfield/eval/frame_stats.h"
#include "farfield/gen/camera_path.h"
#include "farfield/gpu/context.h"
#include "farfield/image/metrics.h"
#include "farfield/scene/scene.h"

namespace farfield::eval {

inline constexpr double kPsnrCapDb = 99.0;

struct BenchOptions {
  std::vector<std::string> modes{"full", "culled"};  // "full" is added first when missing (the baseline)
  int width = 640;
  int height = 360;
  size_t frames = 0;   // measure the first N frames of the path (after stride); 0 = all
  size_t stride = 1;   // take every stride-th path frame
  bool reference = false;
  int bad_pixel_threshold = 8;  // 8-bit units
  // Sample frames saved under out_dir/frames, evenly spaced, and with samples > 0 also the first measured frame in which
  // a mode drew an impostor (FrameRecord::impostors), when it is not one of them; 0 = none.
  int samples = 4;
  std::string out_dir;          // where sample frames go; "" = none saved
  std::map<std::string, std::string> mode_options;  // ModeContext::options
  std::string scene_label;      // for the outputs, e.g. the SCENE argument
  std::string path_label;       // e.g. the path file
  float near_plane = 0.5f;      // metres
  float far_plane = 20000.0f;
  // The error bound every mode's parallax error is checked against (pixels, > 0); unset = each mode's own
  // info()["error_bound_px"], if any.
  std::optional<double> error_px;
  // Renders per mode and frame; the frame's times are those of the fastest render (the machine's noise removed; a
  // mode's first render of a frame also carries its loads, which later renders then skip: see the mode's info for
  // load times). The repeats are whole passes over the path after the first (timing only), so a frame's renders are
  // seconds apart and a slow spell of the machine does not slow all of them. >= 1.
  int repeats = 1;
  // The frame budget (ms, > 0): frames whose wall time exceeds it are counted per mode; unset = not checked.
  std::optional<double> t_max_ms;
};

struct ModeResult {
  std::string name;
  std::vector<FrameRecord> frames;            // in measurement order (= path order), one per measured frame
  std::vector<int> order;                     // position of the mode within each frame's rotation (0 = first)
  std::vector<image::ImageMetrics> errors;    // per frame, against the reference (empty without one);
                                              // psnr_db capped at kPsnrCapDb
  FrameSummary wall;
  FrameSummary gpu;
  FrameSummary cpu;   // Farfield's own CPU time per frame (FrameRecord::cpu_ms)
  CallSummary calls;  // GL calls, uploads and synchronisations per frame
  double mean_triangles = 0.0;
  double mean_draw_calls = 0.0;
  double mean_objects = 0.0;
  double speedup_vs_full = 0.0;
  bool has_errors = false;
  double psnr_db_mean = 0.0;
  double psnr_db_min = 0.0;
  double ssim_mean = 0.0;
  double bad_pixel_share_mean = 0.0;
  // Cracks (Sillion 1997, section 3.1): per frame, with a reference, the share of pixels where the reference shows
  // geometry (object id != 0) and the mode's frame shows sky (id 0); bench.json "crack_share_mean".
  std::vector<double> crack_shares;
  double crack_share_mean = 0.0;
  // Parallax error (eval/parallax_error.h): per frame, with a reference, the 99th percentile over the pixels that
  // show an object of how far (pixels) that object is from where the reference shows it (object_percentile_px); NaN
  // for frames whose item buffer holds ids that are no scene object (impostors drawn with one id of their own).
  // bench.json "parallax_p99_px_mean"/"_max".
  std::vector<double> parallax_px;
  bool has_parallax = false;   // at least one frame measured
  double parallax_px_mean = 0.0;
  double parallax_px_max = 0.0;
  // The error bound (see the top of this file): its value and where it came from ("--error-px", "mode"), unset
  // without one. over_bound per frame: 1 parallax above the bound, 0 within it, -1 not checked (no bound, no
  // reference, parallax not measurable). Counts over the frames.
  std::optional<double> error_bound_px;
  std::string error_bound_source;
  std::vector<int> over_bound;
  size_t frames_over_bound = 0;
  size_t frames_checked = 0;
  // Frames whose wall time exceeds BenchOptions::t_max_ms (0 without it).
  size_t frames_over_tmax = 0;
  // A governed mode (FrameRecord::governor_level >= 0 on a frame): frames drawn with a relaxed bound
  // (bound_scale > 1) and the largest bound_scale; over_bound checks each frame against the bound it kept.
  bool governed = false;
  size_t frames_relaxed = 0;
  double bound_scale_max = 1.0;
  // Popping (eval/temporal_error.h): per frame, with a reference, NaN for the first measured frame. The summary is
  // over the frames that have a value.
  std::vector<double> popping;
  bool has_popping = false;
  FrameSummary popping_summary;
  std::map<std::string, double> info;  // Mode::info()
};

// Fills a mode's summaries from its per-frame records (wall, GPU, image error, parallax, bound, popping). Reads
// `info` for the mode's own bound when error_px is unset. runBench calls it; public for tests.
void summarizeModeResult(ModeResult& mode, std::optional<double> error_px);

struct SampleFrame {
  size_t path_frame = 0;
  std::string reference_png;                  // relative to out_dir; "" without a reference
  std::map<std::string, std::string> mode_png;  // mode -> PNG relative to out_dir
  std::map<std::string, std::string> diff_png;  // mode -> heat map PNG relative to out_dir (with a reference)
};

struct MachineInfo {
  std::string hostname;
  std::string os;   // uname: sysname release machine
  std::string cpu;  // /proc/cpuinfo model name
  unsigned logical_cores = 0;
};
MachineInfo machineInfo();

struct BenchResult {
  std::string scene;
  std::string path;
  size_t path_frames = 0;           // frames in the camera path
  std::vector<size_t> frame_indices;  // the path frames measured
  int width = 0;
  int height = 0;
  std::string renderer;
  std::string date;  // ISO 8601 UTC
  MachineInfo machine;
  std::string allocator;          // core/allocator.h: currentAllocatorSettings().description during the run
  bool allocator_applied = false;
  bool reference = false;
  bool baseline_added = false;  // "full" was not asked for and was added as the baseline
  int bad_pixel_threshold = 8;
  int repeats = 1;                  // BenchOptions::repeats
  std::optional<double> t_max_ms;   // BenchOptions::t_max_ms
  std::vector<ModeResult> modes;  // "full" first, then the asked order
  std::vector<SampleFrame> samples;
  std::vector<std::string> plots;  // PNGs relative to out_dir (filled by runPlotScript)

  const ModeResult* mode(const std::string& name) const;
};

// Makes the context current and runs the benchmark. Throws farfield::Error for unknown modes (before rendering
// anything, listing the known ones), bad options, an empty path or an unusable camera in it.
BenchResult runBench(gpu::Context& context, const scene::Scene& scene, const gen::CameraPath& path,
                     const BenchOptions& options);

void writeBenchJson(const BenchResult& result, const std::string& file);
// A markdown table (one row per mode) with a short header (scene, size, frames, renderer, date, notes).
void writeBenchMarkdown(const BenchResult& result, const std::string& file);
// One row per frame per mode: frame,path_frame,mode,order,wall_ms,gpu_ms,triangles,draw_calls,objects,
// psnr_db,ssim,bad_pixel_share,parallax_p99_px,over_bound,popping,cpu_ms,driver_ms,gl_calls,dispatches,upload_bytes,
// syncs,governor_level,predicted_ms,corrected_ms,bound_scale,impostors (error columns empty without a reference;
// over_bound is 1 or 0, "-" without a bound, empty when not measured; popping is empty for the first frame;
// cpu_ms..syncs empty where GL calls were not counted; governor_level..bound_scale empty for a mode without a
// governor; impostors 1 where the frame drew an impostor, 0 where not, empty for a mode that draws none by design).
void writeFramesCsv(const BenchResult& result, const std::string& file);
// bench.json, bench.md and frames.csv into out_dir (created if missing).
void writeBenchOutputs(const BenchResult& result, const std::string& out_dir);

// Runs `PYTHON SCRIPT OUT_DIR` (tools/plot_bench.py) to draw frame_time.png, error.png, parallax.png and
// popping.png (the last three with a reference), and governor.png (with a governed mode), from frames.csv. PYTHON is
// the first of: the given interpreter, $FF_PYTHON, python3, /usr/bin/python3 that can import matplotlib.
// Returns the plots written (relative to out_dir); warns (never throws) when none could be drawn.
std::vector<std::string> runPlotScript(const std::string& out_dir, const std::string& script,
                                       const std::string& python = "");

// A markdown report: the table, the plots and the sample frames embedded as images with links relative to the
// report's directory. Reads result.plots and result.samples (files under out_dir).
void writeReport(const BenchResult& result, const std::string& out_dir, const std::string& report_file);

}  // namespace farfield::eval
