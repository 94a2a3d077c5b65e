// farfield render SCENE --eye x,y,z --at x,y,z [--up x,y,z] --fov DEG --size WxH -o frame.png
//                [--depth depth.pfm] [--ids ids.png]
// Timed (wall and GPU ms of the second of two renders); the allocator is set up for timing first
// (farfield/core/allocator.h).
#include <cstdio>
#include <memory>

#include "cli_util.h"
#include "command.h"
#include "farfield/core/allocator.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/renderer.h"
#include "farfield/image/png_io.h"
#include "farfield/scene/import.h"

namespace farfield::app {
namespace {

struct RenderArgs {
  std::string scene;
  std::string eye = "0,-10,5";
  std::string at = "0,0,0";
  std::string up = "0,0,1";
  float fov_deg = 60.0f;
  std::string size = "512x512";
  std::string output;
  std::string depth;
  std::string ids;
  float near_plane = 0.1f;
  float far_plane = 20000.0f;
  bool item_buffer = false;
};

void runRender(const RenderArgs& args) {
  const AllocatorSettings allocator = configureTimingAllocator();
  scene::ImportStats import_stats;
  scene::Scene scene = scene::loadScene(args.scene, {}, &import_stats);
  Camera camera;
  camera.eye = parseVec3("--eye", args.eye);
  camera.at = parseVec3("--at", args.at);
  camera.up = parseVec3("--up", args.up);
  camera.fov_y = float(degToRad(args.fov_deg));
  const IVec2 size = parseSize("--size", args.size);
  camera.width = size.x;
  camera.height = size.y;
  camera.near_plane = args.near_plane;
  camera.far_plane = args.far_plane;
  camera.validate("camera (--eye/--at/--up/--fov/--size)");

  gpu::Context& context = gpu::sharedHeadlessContext();
  gpu::GpuScene gpu_scene(scene);
  gpu::Renderer renderer;
  gpu::RenderTarget target(camera.width, camera.height);
  const auto items = gpu_scene.drawItems();
  const auto mode = args.item_buffer ? gpu::RenderMode::ItemBuffer : gpu::RenderMode::Shaded;
  renderer.render(camera, items, target, mode);  // warm-up: first frame includes shader and upload costs
  const gpu::FrameStats stats = renderer.render(camera, items, target, mode);

  ensureParentDirectory(args.output);
  image::writePng(args.output, target.readColor());
  if (!args.depth.empty()) {
    ensureParentDirectory(args.depth);
    image::writePfm(args.depth, target.readDepth());
  }
  if (!args.ids.empty()) {
    ensureParentDirectory(args.ids);
    image::writeIdPng(args.ids, target.readIds());
  }
  std::printf("renderer:   %s\n", context.description().c_str());
  std::printf("frame:      %s (%dx%d)\n", args.output.c_str(), camera.width, camera.height);
  std::printf("triangles:  %llu\n", (unsigned long long)stats.triangles);
  std::printf("draw calls: %u\n", stats.draw_calls);
  std::printf("objects:    %u\n", stats.objects);
  std::printf("wall ms:    %.3f\n", stats.wall_ms);
  std::printf("gpu ms:     %.3f\n", stats.gpu_ms);
  std::printf("malloc:     %s\n", allocator.description.c_str());
  for (const std::string& w : import_stats.warnings()) std::printf("warning:    %s\n", w.c_str());
}

const RegisterCommand reg("render", [](CLI::App& app) {
  auto args = std::make_shared<RenderArgs>();
  auto* cmd = app.add_subcommand("render", "Render one frame of a scene from a camera, with timings.");
  cmd->add_option("scene", args->scene, "Scene file (glTF, OBJ, PLY, AC3D, ...) or builtin:NAME")->required();
  cmd->add_option("--eye", args->eye, "Camera position x,y,z (metres, Z up)")->capture_default_str();
  cmd->add_option("--at", args->at, "Look-at point x,y,z")->capture_default_str();
  cmd->add_option("--up", args->up, "Up vector x,y,z")->capture_default_str();
  cmd->add_option("--fov", args->fov_deg, "Vertical field of view, degrees")->capture_default_str();
  cmd->add_option("--size", args->size, "Image size WxH")->capture_default_str();
  cmd->add_option("--near", args->near_plane, "Near plane, metres")->capture_default_str();
  cmd->add_option("--far", args->far_plane, "Far plane, metres")->capture_default_str();
  cmd->add_option("-o,--output", args->output, "Output PNG")->required();
  cmd->add_option("--depth", args->depth, "Also write window depth (reversed Z, 0 = far) as PFM");
  cmd->add_option("--ids", args->ids, "Also write the object-id buffer as a false-colour PNG");
  cmd->add_flag("--item-buffer", args->item_buffer, "Render in item-buffer mode (ids only, flat colours)");
  cmd->callback([args] { runRender(*args); });
});

}  // namespace
}  // namespace farfield::app
