// Embedding Farfield's walkthrough in a render loop, the way an engine does (no benchmark harness, no CLI):
//
//   embed_walkthrough CITY.glb DATABASE PATH.json [ERROR_PX] [OUT.png]
//
// CITY.glb and its DATABASE come from `farfield gen city` (or an importer) and `farfield bake --pipeline
// pvs,near-far,mmi`; PATH.json from `farfield path street`. Each frame: the camera goes in, a FramePlan comes out
// (the objects drawn as geometry, the impostors' draw items and, per layer, impostor or geometry and why); the
// GPU-driven frame (gpu::GpuCuller over the scene's arena) culls and draws the geometry's clusters with no CPU-GPU
// round trip, and the renderer draws the impostors on top. The program prints what the walkthrough decided and what
// the GPU drew (read frames later, never waited for), and writes the last frame.
#include <algorithm>
#include <cstdio>
#include <cstdint>
#include <exception>
#include <string>
#include <variant>

#include "farfield/core/error.h"
#include "farfield/gen/camera_path.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/gpu_culler.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/renderer.h"
#include "farfield/image/png_io.h"
#include "farfield/runtime/walkthrough.h"
#include "farfield/scene/bvh.h"
#include "farfield/scene/import.h"

int main(int argc, char** argv) {
  using namespace farfield;
  if (argc < 4) {
    std::fprintf(stderr, "usage: %s CITY.glb DATABASE PATH.json [ERROR_PX] [OUT.png]\n", argv[0]);
    return 2;
  }
  try {
    // The engine's side: a context, its scene on the GPU, a renderer and a target.
    std::unique_ptr<gpu::Context> context = gpu::Context::create();
    context->makeCurrent();
    const scene::Scene scene = scene::loadScene(argv[1]);
    const gpu::GpuScene gpu_scene(scene);
    const scene::Bvh bvh(scene);
    gpu::Renderer renderer;
    const int width = 640, height = 360;
    gpu::RenderTarget target(width, height);
    const gen::CameraPath path = gen::loadCameraPath(argv[3]);

    // Farfield's side: the walkthrough over the database, with the user's error bound, planning the geometry as
    // objects for the GPU-driven frame (geometry_items = true would give draw items culled on the CPU instead).
    runtime::WalkthroughOptions options;
    options.database = argv[2];
    if (argc > 4) options.error_px = std::stod(argv[4]);
    options.geometry_items = false;
    runtime::Walkthrough walkthrough(scene, gpu_scene, bvh, renderer, options);
    std::printf("error bound: %.2f px\n", walkthrough.errorBoundPx());
    const gpu::SceneArena arena(scene);  // every mesh in shared buffers, cut into clusters
    gpu::GpuCuller culler(arena);

    size_t impostor_layers = 0, geometry_layers = 0;
    uint64_t version = ~uint64_t(0), gpu_frames = 0, gpu_triangles = 0, gpu_hidden = 0;
    for (size_t f = 0; f < path.frames.size(); ++f) {
      const Camera camera = path.camera(f, width, height);
      const runtime::FramePlan& plan = walkthrough.plan(camera);
      // The engine draws the plan: the geometry's objects through the GPU culler (only a change of the list is
      // sent), then the impostors with the renderer. Nothing here waits for the GPU.
      if (plan.geometry_version != version) {
        culler.setObjects(plan.geometry_objects);
        version = plan.geometry_version;
      }
      target.bind();
      target.clear(renderer.light().sky_color);
      culler.draw(camera, target, gpu::RenderMode::Shaded, renderer.light());
      renderer.draw(camera, plan.items, target);
      for (const gpu::GpuCullStats& s : culler.finishedStats()) {  // earlier frames', as the GPU finishes them
        ++gpu_frames;
        gpu_triangles += s.triangles;
        gpu_hidden += s.occlusion_culled;
      }
      for (const runtime::LayerDecision& d : plan.layers) {
        impostor_layers += std::holds_alternative<runtime::LayerAsImpostor>(d) ? 1 : 0;
        geometry_layers += std::holds_alternative<runtime::LayerAsGeometry>(d) ? 1 : 0;
      }
      if (f % 50 == 0 || f + 1 == path.frames.size())
        std::printf("frame %4zu: cell %u%s, %zu layers as geometry to keep %.2f px, %llu + %llu triangles\n", f,
                    plan.report.cell, plan.report.baked ? "" : " (not baked)", plan.report.layers_as_geometry,
                    plan.report.bound_px, static_cast<unsigned long long>(plan.report.geometry_triangles),
                    static_cast<unsigned long long>(plan.report.impostor_triangles));
    }
    std::printf("layers drawn as impostors %zu times, as geometry %zu times\n", impostor_layers, geometry_layers);
    std::printf("GPU: %llu frames counted, %.0f geometry triangles and %.0f hidden clusters a frame\n",
                static_cast<unsigned long long>(gpu_frames), double(gpu_triangles) / double(std::max<uint64_t>(gpu_frames, 1)),
                double(gpu_hidden) / double(std::max<uint64_t>(gpu_frames, 1)));
    if (argc > 5) image::writePng(argv[5], target.readColor());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
}
