// Embedding Farfield's walkthrough in a render loop, the way an engine does (no benchmark harness, no CLI):
//
//   embed_walkthrough CITY.glb DATABASE PATH.json [ERROR_PX] [OUT.png]
//
// CITY.glb and its DATABASE come from `farfield gen city` (or an importer) and `farfield bake --pipeline
// pvs,near-far,mmi`; PATH.json from `farfield path street`. Each frame: the camera goes in, a FramePlan comes out
// (the draw items and, per layer, impostor or geometry and why), the engine draws the items. The program prints
// what the walkthrough decided and kept, and writes the last frame.
#include <cstdio>
#include <cstdint>
#include <exception>
#include <span>
#include <string>
#include <variant>

#include "farfield/core/error.h"
#include "farfield/gen/camera_path.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/occlusion_culler.h"
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

    // Farfield's side: the walkthrough over the database, with the user's error bound.
    runtime::WalkthroughOptions options;
    options.database = argv[2];
    if (argc > 4) options.error_px = std::stod(argv[4]);
    runtime::Walkthrough walkthrough(scene, gpu_scene, bvh, renderer, options);
    std::printf("error bound: %.2f px\n", walkthrough.errorBoundPx());

    size_t impostor_layers = 0, geometry_layers = 0;
    uint64_t hidden_triangles = 0;
    gpu::OcclusionCuller occlusion;  // optional: drops the plan's geometry hidden behind its nearest items (exact)
    for (size_t f = 0; f < path.frames.size(); ++f) {
      const Camera camera = path.camera(f, width, height);
      const runtime::FramePlan& plan = walkthrough.plan(camera);
      // The engine draws the plan: its geometry items (the first geometry_items, with their bounds) through the
      // occlusion culler, which draws the nearest of them at once, then the rest of the geometry and the impostors.
      target.bind();
      target.clear(renderer.light().sky_color);
      const std::span<const gpu::DrawItem> items(plan.items);
      hidden_triangles += occlusion
                              .draw(renderer, camera, items.first(plan.geometry_items), plan.geometry_bounds, target,
                                    items.subspan(plan.geometry_items))
                              .hidden_triangles;
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
    std::printf("layers drawn as impostors %zu times, as geometry %zu times; %llu geometry triangles hidden\n",
                impostor_layers, geometry_layers, static_cast<unsigned long long>(hidden_triangles));
    if (argc > 5) image::writePng(argv[5], target.readColor());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
}
