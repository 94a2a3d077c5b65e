// Embedding Farfield's walkthrough in a render loop, the way an engine does (no benchmark harness, no CLI):
//
//   embed_walkthrough CITY.glb DATABASE PATH.json [ERROR_PX] [OUT.png] [T_MAX_MS]
//
// CITY.glb and its DATABASE come from `farfield gen city` (or an importer) and `farfield bake --pipeline
// pvs,near-far,mmi`; PATH.json from `farfield path street`. Each frame: the camera goes in, a FramePlan comes out
// (the objects drawn as geometry, the impostors' draw items and, per layer, impostor or geometry and why); the
// GPU-driven frame (gpu::GpuCuller over the scene's arena) culls and draws the geometry's clusters with no CPU-GPU
// round trip, and the renderer draws the impostors on top. The program prints what the walkthrough decided and what
// the GPU drew (read frames later, never waited for), and writes the last frame.
//
// With T_MAX_MS, a frame governor keeps that budget (runtime/governor_loop.h): the arena gets simplified levels, the
// first view is drawn at each level with waits (the engine's loading frame: the calibration), and then each frame's
// level is chosen before it is drawn from the model and the GPU times of earlier frames, read two frames late. The
// last level, for a budget the simplified geometry cannot keep, draws at half the resolution and scales the frame up
// (gpu::TargetUpscaler, an engine's dynamic resolution); it keeps twice the bound, and says so (relaxed).
#include <algorithm>
#include <cstdio>
#include <cstdint>
#include <exception>
#include <map>
#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/gen/camera_path.h"
#include "farfield/gpu/context.h"
#include "farfield/core/timer.h"
#include "farfield/gpu/gpu_culler.h"
#include "farfield/gpu/gpu_timer.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/renderer.h"
#include "farfield/gpu/target_upscaler.h"
#include "farfield/image/png_io.h"
#include "farfield/runtime/governor_loop.h"
#include "farfield/runtime/walkthrough.h"
#include "farfield/scene/bvh.h"
#include "farfield/scene/import.h"

int main(int argc, char** argv) {
  using namespace farfield;
  if (argc < 4) {
    std::fprintf(stderr, "usage: %s CITY.glb DATABASE PATH.json [ERROR_PX] [OUT.png] [T_MAX_MS]\n", argv[0]);
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
    // Every mesh in shared buffers, cut into clusters; with a budget, simplified levels too.
    const double t_max_ms = argc > 6 ? std::stod(argv[6]) : 0.0;
    gpu::ArenaOptions arena_options;
    arena_options.lod_ratio = t_max_ms > 0.0 ? 0.25f : 0.0f;
    const gpu::SceneArena arena(scene, arena_options);
    gpu::GpuCuller culler(arena);

    // The frame governor's levels: the simplified geometry under 0, 1, 2 and 4 pixels, each keeping max(bound, px),
    // then the 4 px geometry at half the resolution, keeping twice that (a pixel there is two of the frame's).
    struct Level {
      float lod_px, scale;
    };
    const std::vector<Level> levels_drawn{{0.0f, 1.0f}, {1.0f, 1.0f}, {2.0f, 1.0f}, {4.0f, 1.0f}, {4.0f, 0.5f}};
    gpu::RenderTarget half(width / 2, height / 2);
    std::unique_ptr<gpu::TargetUpscaler> upscaler;
    std::unique_ptr<runtime::GovernorLoop> governor;
    if (t_max_ms > 0.0) {
      upscaler = std::make_unique<gpu::TargetUpscaler>();
      std::vector<runtime::LoopLevel> levels;
      for (const Level& l : levels_drawn)
        levels.push_back({{"simplified to " + std::to_string(l.lod_px) + " px at " + std::to_string(l.scale),
                           std::max(1.0, double(l.lod_px) / std::max(walkthrough.errorBoundPx(), 1e-9)) / l.scale},
                          double(width) * double(height) * l.scale * l.scale});
      runtime::GovernorLoopOptions loop;
      loop.governor.t_max_ms = t_max_ms;
      governor = std::make_unique<runtime::GovernorLoop>(std::move(levels), loop);
    }
    const auto drawFrame = [&](const Camera& camera, const runtime::FramePlan& plan, size_t level) {
      const Level& l = levels_drawn[level];
      culler.setLodErrorPx(l.lod_px);
      gpu::RenderTarget& into = l.scale < 1.0f ? half : target;
      Camera c = camera;
      c.width = into.width();
      c.height = into.height();
      into.bind();
      into.clear(renderer.light().sky_color);
      culler.draw(c, into, gpu::RenderMode::Shaded, renderer.light());
      renderer.draw(c, plan.items, into);
      if (&into != &target) upscaler->draw(half, target, gpu::TargetUpscaler::Channels::ColorAndIds);
    };
    if (governor) {
      // The calibration: the first view at every level, each waited for (the public wait: a 1 x 1 render).
      const Camera camera = path.camera(0, width, height);
      const runtime::FramePlan& plan = walkthrough.plan(camera);
      culler.setObjects(plan.geometry_objects);
      Camera tiny = camera;
      tiny.width = tiny.height = 1;
      gpu::RenderTarget tiny_target(1, 1);
      for (int round = 0; round <= 3; ++round)
        for (size_t level = 0; level < levels_drawn.size(); ++level) {
          Stopwatch clock;
          drawFrame(camera, plan, level);
          renderer.render(tiny, {}, tiny_target);
          const double ms = clock.milliseconds();
          const std::vector<gpu::GpuCullStats> stats = culler.finishedStats();
          if (round > 0 && !stats.empty()) governor->calibrationSample(level, double(stats.back().triangles), ms);
        }
      governor->finishCalibration();
      culler.resetHistory();
    }
    const uint64_t first_culler_frame = culler.frames();
    gpu::GpuTimer timers[3];  // a frame's GPU time is read two frames later
    size_t relaxed = 0;

    size_t impostor_layers = 0, geometry_layers = 0;
    uint64_t version = ~uint64_t(0), gpu_frames = 0, gpu_triangles = 0, gpu_hidden = 0;
    for (size_t f = 0; f < path.frames.size(); ++f) {
      const Camera camera = path.camera(f, width, height);
      const runtime::FramePlan& plan = walkthrough.plan(camera);
      size_t level = 0;
      double spare_ms = 2.0;  // without a budget: a fixed share of each frame for loading what later frames need
      if (governor) {
        if (f >= 2) governor->frameMeasured(f - 2, timers[(f - 2) % 3].elapsedMs());
        const runtime::GovernorDecision decision = governor->decide(f);
        level = decision.level;
        relaxed += decision.relaxed ? 1 : 0;
        spare_ms = t_max_ms - decision.corrected_ms;  // what the frame is expected to leave of the budget
        timers[f % 3].begin();
      }
      // The engine draws the plan: the geometry's objects through the GPU culler (only a change of the list is
      // sent), then the impostors with the renderer. Nothing here waits for the GPU.
      if (plan.geometry_version != version) {
        culler.setObjects(plan.geometry_objects);
        version = plan.geometry_version;
      }
      drawFrame(camera, plan, level);
      if (governor) timers[f % 3].end();
      // The cells the viewer may enter next, read on the walkthrough's thread, uploaded in the time the frame spares,
      // so that entering one uploads nothing.
      if (spare_ms > 0.0) walkthrough.loadAhead(camera, spare_ms);
      for (const gpu::GpuCullStats& s : culler.finishedStats()) {  // earlier frames', as the GPU finishes them
        if (governor && s.frame >= first_culler_frame) governor->frameTriangles(s.frame - first_culler_frame, double(s.triangles));
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
    {
      const std::map<std::string, double> w = walkthrough.statistics();
      const auto at = [&](const char* key) { return w.count(key) ? w.at(key) : 0.0; };
      std::printf("cells: %.0f entered, %.0f of them uploaded ahead in spare time, %.0f partly; slowest load in a frame "
                  "%.2f ms\n", at("cell_entries"), at("cells_entered_uploaded"), at("cells_entered_partly_uploaded"),
                  at("cell_load_ms_max"));
    }
    std::printf("GPU: %llu frames counted, %.0f geometry triangles and %.0f hidden clusters a frame\n",
                static_cast<unsigned long long>(gpu_frames), double(gpu_triangles) / double(std::max<uint64_t>(gpu_frames, 1)),
                double(gpu_hidden) / double(std::max<uint64_t>(gpu_frames, 1)));
    if (governor) {
      const runtime::FrameGovernor::Statistics& s = governor->governor().statistics();
      std::printf("governor: t_max %.2f ms, frames per level", t_max_ms);
      for (size_t l = 0; l < levels_drawn.size(); ++l) std::printf(" %zu", s.frames_at_level[l]);
      std::printf(", relaxed %zu of %zu, measured over t_max %zu\n", relaxed, path.frames.size(), s.measured_over);
    }
    if (argc > 5) image::writePng(argv[5], target.readColor());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
}
