// farfield cull-check SCENE --path PATH [--size WxH] [--stride K] [--frames N] [--gpu-occlusion on|off]
//                     [--occlusion-margin M] [-o OUT]
// The GPU-culled frame against the frustum-culled frame on every frame of a path (eval/cull_check.h); exit code 1
// when a frame shows a different object anywhere outside coplanar ties, or its PSNR is under 60 dB.
#include <cstdio>
#include <memory>

#include "cli_util.h"
#include "command.h"
#include "farfield/core/error.h"
#include "farfield/eval/cull_check.h"
#include "farfield/scene/import.h"

namespace farfield::app {
namespace {

struct CullCheckArgs {
  std::string scene, path, size = "640x360", output, occlusion = "on";
  eval::CullCheckOptions options;
};

void runCullCheckCommand(CullCheckArgs& args) {
  const IVec2 size = parseSize("--size", args.size);
  args.options.width = size.x;
  args.options.height = size.y;
  if (args.occlusion != "on" && args.occlusion != "off")
    throw Error("--gpu-occlusion", "must be on or off, got '" + args.occlusion + "'");
  args.options.cull.occlusion = args.occlusion == "on";
  const gen::CameraPath path = gen::loadCameraPath(args.path);
  const scene::Scene scene = scene::loadScene(args.scene);
  const eval::CullCheckResult r = eval::runCullCheck(gpu::sharedHeadlessContext(), scene, path, args.options);
  std::printf("renderer:         %s\n", r.renderer.c_str());
  std::printf("frames:           %zu at %dx%d\n", r.frames.size(), r.width, r.height);
  std::printf("differing frames: %zu (at most %llu pixels showing another object, tie pixels left out)\n",
              r.frames_differing, static_cast<unsigned long long>(r.differing_max));
  std::printf("PSNR min:         %.2f dB\n", r.psnr_db_min);
  std::printf("tie pixels:       %.4f%% (coplanar surfaces of different objects: their winner depends on draw order)\n",
              100.0 * r.tie_share_mean);
  std::printf("colour ties:      %.4f%% (coplanar faces of one object: the colour depends on draw order)\n",
              100.0 * r.colour_tie_share_mean);
  if (!args.output.empty()) {
    eval::writeCullCheck(r, args.scene, args.path, args.output);
    std::printf("wrote %s/cullcheck.{json,md}\n", args.output.c_str());
  }
  std::printf("result:           %s\n", r.passed ? "passed" : "FAILED");
  if (!r.passed) std::exit(1);
}

const RegisterCommand reg("cull-check", [](CLI::App& app) {
  auto args = std::make_shared<CullCheckArgs>();
  auto* cmd = app.add_subcommand("cull-check",
                                 "Check the GPU-culled frame against the frustum-culled frame on every frame of a "
                                 "camera path: the same object at every pixel outside coplanar ties, PSNR >= 60 dB.");
  cmd->add_option("scene", args->scene, "Scene")->required();
  cmd->add_option("--path", args->path, "Camera path (farfield path)")->required();
  cmd->add_option("--size", args->size, "Frame size WxH")->capture_default_str();
  cmd->add_option("--stride", args->options.stride, "Every K-th path frame")->capture_default_str();
  cmd->add_option("--frames", args->options.frames, "At most N frames (0: all)")->capture_default_str();
  cmd->add_option("--gpu-occlusion", args->occlusion, "The hierarchical-Z test: on or off")->capture_default_str();
  cmd->add_option("--occlusion-margin", args->options.cull.occlusion_margin,
                  "Relative depth margin of the occlusion test (negative values break it: the check must then fail)")
      ->capture_default_str();
  cmd->add_option("-o,--output", args->output, "Directory for cullcheck.json and cullcheck.md");
  cmd->callback([args] { runCullCheckCommand(*args); });
});

}  // namespace
}  // namespace farfield::app
