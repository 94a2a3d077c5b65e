// farfield bench SCENE --path path.json --modes full,culled,... [--reference] [--size WxH] [--frames N]
//                [--stride K] [--samples K] -o OUTDIR [--report FILE] [--no-plots] [--plot-script FILE]
//                [--python EXE] [--mode-option key=value]... [--impostors DIR] [--error-px PX]
// The walkthrough benchmark (see farfield/eval/bench.h): all modes interleaved over the same frames, with
// bench.json, bench.md, frames.csv, plots, sample frames and a report in OUTDIR. --impostors DIR is the impostor
// store of `farfield bake` for the depth-mesh and grid-mesh modes (the mode option impostor_dir; see
// farfield/eval/impostor_mode.h). --error-px is the error bound the frames are checked against (default: each
// mode's own). The allocator is set up for timing first (farfield/core/allocator.h).
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <sstream>

#include "cli_util.h"
#include "command.h"
#include "farfield/core/allocator.h"
#include "farfield/core/error.h"
#include "farfield/eval/bench.h"
#include "farfield/eval/mode.h"
#include "farfield/gen/camera_path.h"
#include "farfield/gpu/context.h"
#include "farfield/eval/impostor_mode.h"
#include "farfield/scene/import.h"

namespace fs = std::filesystem;

namespace farfield::app {
namespace {

struct BenchArgs {
  std::string scene;
  std::string path;
  std::string modes = "full,culled";
  bool reference = false;
  std::string size = "640x360";
  size_t frames = 0;
  size_t stride = 1;
  int samples = 4;
  std::string out_dir;
  std::string report;
  bool no_plots = false;
  std::string plot_script;
  std::string python;
  std::vector<std::string> mode_options;
  std::string memory_budget_mb;  // --memory-budget: the mode option memory_budget_mb
  std::string impostors;
  float near_plane = 0.5f;
  float far_plane = 20000.0f;
  double error_px = 0.0;  // 0 = not given
  double t_max = 0.0;     // 0 = not given
  int repeats = 1;
};

std::vector<std::string> splitModes(const std::string& text) {
  std::vector<std::string> modes;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');) {
    item.erase(0, item.find_first_not_of(" \t"));
    item.erase(item.find_last_not_of(" \t") + 1);
    if (item.empty()) throw Error("--modes", "empty mode name in '" + text + "' (expected e.g. full,culled)");
    modes.push_back(item);
  }
  if (modes.empty()) throw Error("--modes", "no modes given");
  return modes;
}

// tools/plot_bench.py: $FF_PLOT_SCRIPT, else the source tree this file was compiled from (__FILE__ is absolute
// under CMake), else next to an installed or build-tree executable.
std::string findPlotScript() {
  if (const char* env = std::getenv("FF_PLOT_SCRIPT"); env && *env) return env;
  std::vector<fs::path> candidates;
  candidates.push_back(fs::path(__FILE__).parent_path() / ".." / ".." / "tools" / "plot_bench.py");
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    candidates.push_back(exe.parent_path() / ".." / "share" / "farfield" / "plot_bench.py");
    candidates.push_back(exe.parent_path() / ".." / ".." / ".." / "tools" / "plot_bench.py");  // build/NAME/bin
    candidates.push_back(exe.parent_path() / ".." / ".." / "tools" / "plot_bench.py");         // build/bin
  }
  for (const fs::path& c : candidates)
    if (fs::exists(c, ec)) return fs::weakly_canonical(c, ec).string();
  return "";
}

void runBenchCommand(const BenchArgs& args) {
  const AllocatorSettings allocator = configureTimingAllocator();
  eval::BenchOptions options;
  const IVec2 size = parseSize("--size", args.size);
  options.width = size.x;
  options.height = size.y;
  options.modes = splitModes(args.modes);
  options.frames = args.frames;
  if (args.stride < 1) throw Error("--stride", "must be at least 1");
  options.stride = args.stride;
  if (args.samples < 0) throw Error("--samples", "must be 0 or more");
  options.samples = args.samples;
  options.reference = args.reference;
  options.out_dir = args.out_dir;
  options.mode_options = eval::parseModeOptions(args.mode_options);
  if (!args.memory_budget_mb.empty()) options.mode_options["memory_budget_mb"] = args.memory_budget_mb;
  if (!args.impostors.empty()) options.mode_options["impostor_dir"] = args.impostors;
  options.scene_label = args.scene;
  options.path_label = args.path;
  if (!(args.near_plane > 0.0f && args.far_plane > args.near_plane))
    throw Error("--near/--far", "need 0 < near < far");
  options.near_plane = args.near_plane;
  options.far_plane = args.far_plane;
  options.repeats = args.repeats;
  if (args.t_max != 0.0) {
    if (!(args.t_max > 0.0)) throw Error("--tmax", "must be a positive number of ms");
    options.t_max_ms = args.t_max;
  }
  if (args.error_px != 0.0) {
    if (!(args.error_px > 0.0)) throw Error("--error-px", "must be a positive number of pixels");
    options.error_px = args.error_px;
  }
  // Cheap checks first: unknown modes or a bad path fail before the scene is loaded.
  eval::checkModeNames(options.modes);
  const gen::CameraPath path = gen::loadCameraPath(args.path);
  const scene::Scene scene = scene::loadScene(args.scene);
  std::error_code ec;
  fs::create_directories(args.out_dir, ec);
  if (ec) throw Error(args.out_dir, "cannot create the output directory: " + ec.message());

  eval::BenchResult result = eval::runBench(gpu::sharedHeadlessContext(), scene, path, options);
  if (!args.no_plots) {
    const std::string script = args.plot_script.empty() ? findPlotScript() : args.plot_script;
    if (!args.plot_script.empty() && !fs::exists(args.plot_script))
      throw Error(args.plot_script, "plot script not found (--plot-script)");
    // The plots read frames.csv, so it is written first; bench.json is written again to list the plots.
    eval::writeBenchOutputs(result, args.out_dir);
    result.plots = eval::runPlotScript(args.out_dir, script, args.python);
  }
  eval::writeBenchOutputs(result, args.out_dir);
  const std::string report = args.report.empty() ? (fs::path(args.out_dir) / "report.md").string() : args.report;
  ensureParentDirectory(report);
  eval::writeReport(result, args.out_dir, report);

  std::printf("renderer: %s\n", result.renderer.c_str());
  std::printf("malloc:   %s\n", allocator.description.c_str());
  std::printf("frames:   %zu of %zu (size %dx%d)\n", result.frame_indices.size(), result.path_frames, result.width,
              result.height);
  if (result.baseline_added) std::printf("note:     \"full\" was not asked for; it ran anyway as the baseline\n");
  std::printf("\n%-16s %10s %10s %10s %10s %12s %9s %10s %8s %12s %12s %9s\n", "mode", "median ms", "p95 ms",
              "p99 ms", "max ms", "triangles", "speedup", "PSNR dB", "cracks", "parallax px", "over bound",
              "popping max");
  for (const eval::ModeResult& m : result.modes) {
    char psnr[32] = "n/a";
    if (m.has_errors) {
      if (m.psnr_db_mean >= eval::kPsnrCapDb)
        std::snprintf(psnr, sizeof(psnr), "identical");
      else
        std::snprintf(psnr, sizeof(psnr), "%.2f", m.psnr_db_mean);
    }
    char cracks[32] = "n/a";
    if (m.has_errors) std::snprintf(cracks, sizeof(cracks), "%.3f%%", 100.0 * m.crack_share_mean);
    char parallax[32] = "n/a";
    if (m.has_parallax) std::snprintf(parallax, sizeof(parallax), "%.2f", m.parallax_px_mean);
    char over[48] = "-";
    if (m.error_bound_px && m.frames_checked > 0)
      std::snprintf(over, sizeof(over), "%zu/%zu", m.frames_over_bound, m.frames_checked);
    else if (m.error_bound_px)
      std::snprintf(over, sizeof(over), "n/a");
    char popping[32] = "n/a";
    if (m.has_popping) std::snprintf(popping, sizeof(popping), "%.3f", m.popping_summary.max);
    std::printf("%-16s %10.3f %10.3f %10.3f %10.3f %12.0f %8.2fx %10s %8s %12s %12s %12s\n", m.name.c_str(),
                m.wall.median, m.wall.p95, m.wall.p99, m.wall.max, m.mean_triangles, m.speedup_vs_full, psnr, cracks,
                parallax, over, popping);
  }
  if (result.t_max_ms) {
    std::printf("\nframes over t_max %.2f ms (fastest of %d renders per frame):", *result.t_max_ms, result.repeats);
    for (const eval::ModeResult& m : result.modes)
      std::printf(" %s %zu/%zu;", m.name.c_str(), m.frames_over_tmax, m.frames.size());
    std::printf("\n");
    for (const eval::ModeResult& m : result.modes)
      if (m.governed)
        std::printf("%s: %zu of %zu frames relaxed (drawn at a coarser level), the bound kept up to %.2fx\n",
                    m.name.c_str(), m.frames_relaxed, m.frames.size(), m.bound_scale_max);
  }
  std::printf("\nwrote %s/{bench.json,bench.md,frames.csv}", args.out_dir.c_str());
  for (const std::string& p : result.plots) std::printf(", %s", p.c_str());
  std::printf(", %zu sample frames, report %s\n", result.samples.size(), report.c_str());
}

const RegisterCommand reg("bench", [](CLI::App& app) {
  eval::registerImpostorModes();  // the impostor modes (depth-mesh, grid-mesh), before the mode list below
  auto args = std::make_shared<BenchArgs>();
  auto* cmd = app.add_subcommand("bench", "Walkthrough benchmark: modes interleaved over a camera path, with "
                                          "frame-time statistics, image error, plots and a report.");
  cmd->add_option("scene", args->scene, "Scene file (glTF, OBJ, ...) or builtin:NAME")->required();
  cmd->add_option("--path", args->path, "Camera path JSON")->required();
  cmd->add_option("--modes", args->modes, "Comma-separated modes; full always runs as the baseline. Known: " + [] {
    std::string names;
    for (const auto& n : eval::modeNames()) names += (names.empty() ? "" : ", ") + n;
    return names;
  }())->capture_default_str();
  cmd->add_flag("--reference", args->reference,
                "Also render every frame from full geometry (untimed) and measure each mode's image error");
  cmd->add_option("--size", args->size, "Frame size WxH")->capture_default_str();
  cmd->add_option("--frames", args->frames, "Measure the first N frames (after --stride); 0 = all");
  cmd->add_option("--stride", args->stride, "Take every K-th frame of the path")->capture_default_str();
  cmd->add_option("--samples", args->samples, "Sample frames saved as PNG (evenly spaced)")->capture_default_str();
  cmd->add_option("-o,--output", args->out_dir, "Output directory")->required();
  cmd->add_option("--report", args->report, "Markdown report file (default OUTDIR/report.md)");
  cmd->add_flag("--no-plots", args->no_plots, "Do not run tools/plot_bench.py");
  cmd->add_option("--plot-script", args->plot_script, "Path of plot_bench.py (default: found automatically)");
  cmd->add_option("--python", args->python, "Python interpreter for the plots (default: python3)");
  cmd->add_option("--memory-budget", args->memory_budget_mb, "Impostor modes: MB of the database held in memory "
                                                           "(resident impostors and cells read ahead)");
  cmd->add_option("--mode-option", args->mode_options, "key=value passed to the modes (repeatable)");
  cmd->add_option("--impostors", args->impostors,
                  "Impostor store of farfield bake for the depth-mesh and grid-mesh modes (= --mode-option "
                  "impostor_dir=DIR)");
  cmd->add_option("--repeats", args->repeats, "Renders per frame and mode; the fastest is kept")->capture_default_str();
  cmd->add_option("--tmax", args->t_max, "Frame budget, ms: frames slower than it are counted per mode");
  cmd->add_option("--error-px", args->error_px,
                  "Error bound, pixels: frames whose parallax p99 exceeds it are counted (default: the bound each "
                  "mode reports, if any)");
  cmd->add_option("--near", args->near_plane, "Near plane, metres")->capture_default_str();
  cmd->add_option("--far", args->far_plane, "Far plane, metres")->capture_default_str();
  cmd->callback([args] { runBenchCommand(*args); });
});

}  // namespace
}  // namespace farfield::app
