// farfield walk SCENE --path path.json --mode full|culled|... [--size WxH] [--frames N] [--csv frames.csv]
//               [--frames-dir DIR --every K] [--mode-option key=value]...
// One mode along a camera path: per-frame wall time (to glFinish), GPU time, triangles, draw calls, objects drawn;
// prints median, p95, p99 and max. The allocator is set up for timing first (farfield/core/allocator.h).
#include <cstdio>
#include <memory>

#include "cli_util.h"
#include "command.h"
#include "farfield/core/allocator.h"
#include "farfield/core/error.h"
#include "farfield/eval/mode.h"
#include "farfield/eval/walk.h"
#include "farfield/gen/camera_path.h"
#include "farfield/gpu/context.h"
#include "farfield/eval/impostor_mode.h"
#include "farfield/scene/import.h"

namespace farfield::app {
namespace {

struct WalkArgs {
  std::string scene;
  std::string path;
  std::string mode = "full";
  std::string size = "640x360";
  size_t frames = 0;
  std::string csv;
  std::string frames_dir;
  int every = 10;
  std::vector<std::string> mode_options;
  std::string memory_budget_mb;  // --memory-budget: the mode option memory_budget_mb
  float near_plane = 0.5f;
  float far_plane = 20000.0f;
};

void runWalkCommand(const WalkArgs& args) {
  const AllocatorSettings allocator = configureTimingAllocator();
  eval::WalkOptions options;
  const IVec2 size = parseSize("--size", args.size);
  options.width = size.x;
  options.height = size.y;
  options.mode = args.mode;
  options.frames = args.frames;
  options.frames_dir = args.frames_dir;
  if (args.every < 1) throw Error("--every", "must be at least 1, got " + std::to_string(args.every));
  options.every = args.every;
  options.mode_options = eval::parseModeOptions(args.mode_options);
  if (!args.memory_budget_mb.empty()) options.mode_options["memory_budget_mb"] = args.memory_budget_mb;
  options.near_plane = args.near_plane;
  options.far_plane = args.far_plane;
  if (!(args.near_plane > 0.0f && args.far_plane > args.near_plane))
    throw Error("--near/--far", "need 0 < near < far");
  // Cheap checks first: an unknown mode or a bad path fails before the scene is loaded.
  eval::checkModeNames(std::span<const std::string>(&options.mode, 1));
  const gen::CameraPath path = gen::loadCameraPath(args.path);
  const scene::Scene scene = scene::loadScene(args.scene);

  eval::WalkResult result = eval::runWalk(gpu::sharedHeadlessContext(), scene, path, options);
  if (!args.csv.empty()) {
    ensureParentDirectory(args.csv);
    eval::writeWalkCsv(result, args.csv);
  }
  std::printf("scene:           %s\n", args.scene.c_str());
  std::printf("path:            %s\n", args.path.c_str());
  std::printf("malloc:          %s\n", allocator.description.c_str());
  std::fputs(eval::formatWalkSummary(result).c_str(), stdout);
  if (!args.csv.empty()) std::printf("csv:             %s\n", args.csv.c_str());
  if (!result.written_frames.empty())
    std::printf("frames written:  %zu PNGs in %s\n", result.written_frames.size(), args.frames_dir.c_str());
}

const RegisterCommand reg("walk", [](CLI::App& app) {
  eval::registerImpostorModes();  // the impostor modes (depth-mesh, grid-mesh), before the mode list below
  auto args = std::make_shared<WalkArgs>();
  auto* cmd = app.add_subcommand("walk", "Walk a camera path with one mode; per-frame times and a summary.");
  cmd->add_option("scene", args->scene, "Scene file (glTF, OBJ, ...) or builtin:NAME")->required();
  cmd->add_option("--path", args->path, "Camera path JSON (farfield path ... writes them)")->required();
  cmd->add_option("--mode", args->mode, "Mode: " + [] {
    std::string names;
    for (const auto& n : eval::modeNames()) names += (names.empty() ? "" : ", ") + n;
    return names;
  }())->capture_default_str();
  cmd->add_option("--size", args->size, "Frame size WxH")->capture_default_str();
  cmd->add_option("--frames", args->frames, "Walk only the first N frames of the path (0 = all)");
  cmd->add_option("--csv", args->csv, "Write per-frame numbers to this CSV file");
  cmd->add_option("--frames-dir", args->frames_dir, "Write every K-th frame as PNG into this directory");
  cmd->add_option("--every", args->every, "K for --frames-dir")->capture_default_str();
  cmd->add_option("--memory-budget", args->memory_budget_mb, "Impostor modes: MB of the database held in memory "
                                                           "(resident impostors and cells read ahead)");
  cmd->add_option("--mode-option", args->mode_options, "key=value passed to the mode (repeatable)");
  cmd->add_option("--near", args->near_plane, "Near plane, metres")->capture_default_str();
  cmd->add_option("--far", args->far_plane, "Far plane, metres")->capture_default_str();
  cmd->callback([args] { runWalkCommand(*args); });
});

}  // namespace
}  // namespace farfield::app
