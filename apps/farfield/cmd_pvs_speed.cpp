// farfield pvs-speed SCENE --path PATH [--points N] [--face PX] [--shares 0.05,0.1] [--repeats R] [-o report.json]
// The PVS sampler with and without occlusion culling on the eyes of a camera path: eval/pvs_speed.h.
#include <cstdio>
#include <memory>

#include <nlohmann/json.hpp>

#include "cli_util.h"
#include "command.h"
#include "farfield/core/error.h"
#include "farfield/eval/pvs_speed.h"
#include "farfield/gen/camera_path.h"
#include "farfield/gpu/context.h"
#include "farfield/scene/import.h"
#include "farfield/store/impostor_store.h"

namespace farfield::app {
namespace {

struct PvsSpeedArgs {
  std::string scene, path, output;
  size_t points = 60;
  eval::PvsSpeedOptions options;
};

void runPvsSpeed(PvsSpeedArgs& args) {
  if (args.points == 0) throw Error("--points", "must be at least 1");
  const gen::CameraPath path = gen::loadCameraPath(args.path);
  std::vector<Vec3> eyes;
  const size_t step = std::max<size_t>(1, path.frames.size() / args.points);
  for (size_t i = 0; i < path.frames.size() && eyes.size() < args.points; i += step) eyes.push_back(path.frames[i].eye);
  gpu::sharedHeadlessContext();
  const scene::Scene scene = scene::loadScene(args.scene);
  const gpu::GpuScene gpu_scene(scene);
  const eval::PvsSpeedReport report = eval::measurePvsSpeed(gpu_scene, eyes, args.options);
  std::printf("%zu viewpoints of %s, %d px cube faces, scene %.2f M triangles\n", report.points, args.path.c_str(),
              args.options.pvs.face_size, double(report.scene_triangles) * 1e-6);
  std::printf("%-10s %8s %10s %8s %14s %14s %10s\n", "occlusion", "share", "ms/point", "speedup", "Mtri drawn",
              "objects hidden", "differ");
  for (const eval::PvsSpeedRun& r : report.runs)
    std::printf("%-10s %8.3f %10.1f %7.2fx %14.2f %14llu %10zu\n", r.occlusion ? "on" : "off", r.occluder_share,
                r.ms / double(report.points), report.runs.front().ms / r.ms, double(r.triangles_drawn) * 1e-6,
                static_cast<unsigned long long>(r.objects_hidden), r.mismatched_points);
  if (!args.output.empty()) {
    ensureParentDirectory(args.output);
    store::writeFileAtomic(args.output, report.toJson().dump(1) + "\n");
    std::printf("wrote %s\n", args.output.c_str());
  }
}

const RegisterCommand reg("pvs-speed", [](CLI::App& app) {
  auto args = std::make_shared<PvsSpeedArgs>();
  auto* cmd = app.add_subcommand("pvs-speed",
                                 "Time the PVS sampler's 360-degree item-buffer views with and without occlusion "
                                 "culling on the eyes of a camera path, and check that they see the same objects.");
  cmd->add_option("scene", args->scene, "Scene")->required();
  cmd->add_option("--path", args->path, "Camera path whose eyes are the viewpoints (farfield path)")->required();
  cmd->add_option("--points", args->points, "Viewpoints, evenly spread over the path")->capture_default_str();
  cmd->add_option("--face", args->options.pvs.face_size, "Pixels per side of each cube face")->capture_default_str();
  cmd->add_option("--shares", args->options.occluder_shares,
                  "Occluder shares to try (the first pass's share of a face's triangles)")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--repeats", args->options.repeats, "Renders per viewpoint and run, the fastest kept")
      ->capture_default_str();
  cmd->add_option("-o,--output", args->output, "Report (JSON)");
  cmd->callback([args] { runPvsSpeed(*args); });
});

}  // namespace
}  // namespace farfield::app
