#include "farfield/eval/walk.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "farfield/core/error.h"
#include "farfield/core/progress.h"
#include "farfield/image/png_io.h"
#include "farfield/scene/bvh.h"

namespace farfield::eval {

WalkResult runWalk(gpu::Context& context, const scene::Scene& scene, const gen::CameraPath& path,
                   const WalkOptions& options) {
  checkModeNames(std::span<const std::string>(&options.mode, 1));
  if (path.frames.empty()) throw Error("camera path", "has no frames");
  if (options.every < 1) throw Error("--every", "must be at least 1");
  const size_t count = options.frames == 0 ? path.frames.size() : std::min(options.frames, path.frames.size());
  // Check every camera before the GPU work starts, so a bad frame fails fast.
  for (size_t i = 0; i < count; ++i)
    pathCamera(path, i, options.width, options.height, options.near_plane, options.far_plane);
  if (!options.frames_dir.empty()) std::filesystem::create_directories(options.frames_dir);

  context.makeCurrent();
  WalkResult result;
  result.mode = options.mode;
  result.renderer = context.description();
  result.width = options.width;
  result.height = options.height;

  ModeRunResources run(scene, options.width, options.height, options.mode_options);
  gpu::Renderer& renderer = run.renderer;
  gpu::RenderTarget& target = run.target;
  ModeContext& mode_context = run.context;
  mode_context.ids_read = false;  // a walk reads colour (frame files) and times, never the item buffers
  std::unique_ptr<Mode> mode = createMode(options.mode, mode_context);
  mode->prepare(mode_context);

  FrameRunner runner(renderer, target);
  auto camera_of = [&](size_t i) {
    return pathCamera(path, i, options.width, options.height, options.near_plane, options.far_plane);
  };
  // The first frame pays for shader compilation, texture residency and driver caches; it is not the walk's.
  if (options.warm_up) runner.run(*mode, camera_of(0), 0);

  Progress progress("walk " + options.mode, count);
  result.frames.reserve(count);
  for (size_t i = 0; i < count; ++i) {
    result.frames.push_back(runner.run(*mode, camera_of(i), i));
    if (!options.frames_dir.empty() && i % size_t(options.every) == 0) {
      char name[32];
      std::snprintf(name, sizeof(name), "frame_%05zu.png", i);
      const std::string file = (std::filesystem::path(options.frames_dir) / name).string();
      image::writePng(file, target.readColor());
      result.written_frames.push_back(file);
    }
    progress.advance();
  }
  progress.finish();
  result.info = mode->info();

  summarizeFrames(result);
  return result;
}

void writeWalkCsv(const WalkResult& result, const std::string& file) {
  std::ofstream out(file);
  if (!out) throw Error(file, "cannot open for writing");
  out << "frame,path_frame,mode,wall_ms,gpu_ms,triangles,draw_calls,objects,cpu_ms,driver_ms,gl_calls,dispatches,"
         "upload_bytes,syncs,impostors,governor_level,predicted_ms,corrected_ms,bound_scale\n";
  char line[512];
  for (size_t i = 0; i < result.frames.size(); ++i) {
    const FrameRecord& f = result.frames[i];
    std::snprintf(line, sizeof(line), "%zu,%zu,%s,%.4f,%.4f,%llu,%u,%u,%.4f,%.4f,%llu,%u,%llu,%u,", i, f.path_frame,
                  result.mode.c_str(), f.wall_ms, f.gpu_ms, (unsigned long long)f.triangles, f.draw_calls, f.objects,
                  f.cpu_ms, f.driver_ms, (unsigned long long)f.gl_calls, f.dispatches,
                  (unsigned long long)f.upload_bytes, f.syncs);
    out << line << (f.impostors >= 0 ? std::to_string(f.impostors) : std::string());
    if (f.governor_level >= 0) {
      std::snprintf(line, sizeof(line), ",%d,%.4f,%.4f,%.4f", f.governor_level, f.predicted_ms, f.corrected_ms,
                    f.bound_scale);
      out << line << "\n";
    } else {
      out << ",,,,\n";
    }
  }
  if (!out) throw Error(file, "write failed");
}

std::string formatWalkSummary(const WalkResult& r) {
  char buf[2048];
  std::snprintf(buf, sizeof(buf),
                "mode:            %s\n"
                "renderer:        %s\n"
                "size:            %dx%d\n"
                "frames:          %zu\n"
                "wall ms:         median %.3f  p95 %.3f  p99 %.3f  max %.3f  mean %.3f\n"
                "gpu ms:          median %.3f  p95 %.3f  p99 %.3f  max %.3f\n"
                "own cpu ms:      median %.3f  p95 %.3f  max %.3f (Farfield's own code: wall less driver and waits)\n"
                "triangles:       %.0f (mean per frame)\n"
                "draw calls:      %.1f (mean per frame)\n"
                "objects drawn:   %.1f (mean per frame)\n"
                "percentiles:     linear interpolation between closest ranks\n",
                r.mode.c_str(), r.renderer.c_str(), r.width, r.height, r.frames.size(), r.wall.median, r.wall.p95,
                r.wall.p99, r.wall.max, r.wall.mean, r.gpu.median, r.gpu.p95, r.gpu.p99, r.gpu.max, r.cpu.median,
                r.cpu.p95, r.cpu.max, r.mean_triangles, r.mean_draw_calls, r.mean_objects);
  std::string text = buf;
  if (r.calls.counted) {
    std::snprintf(buf, sizeof(buf),
                  "gl calls:        %.1f (mean per frame), %.1f compute dispatches\n"
                  "uploaded:        %.0f bytes (mean per frame), max %llu\n"
                  "synchronisations: %.2f (mean per frame), max %u, %zu frames with one or more\n",
                  r.calls.gl_calls_mean, r.calls.dispatches_mean, r.calls.upload_bytes_mean,
                  (unsigned long long)r.calls.upload_bytes_max, r.calls.syncs_mean, r.calls.syncs_max,
                  r.calls.frames_with_syncs);
    text += buf;
  }
  const auto info = [&](const char* key) {
    const auto it = r.info.find(key);
    return it == r.info.end() ? 0.0 : it->second;
  };
  if (info("gpu_occlusion_auto") > 0.0) {
    std::snprintf(buf, sizeof(buf),
                  "occlusion:       auto (gpu_occlusion): on in %.0f%% of frames, %s at the end; %.0f probes (%.0f "
                  "on a change of the frame time), %.0f switches\n",
                  100.0 * info("gpu_occlusion_frames"), info("gpu_occlusion_kept") > 0.0 ? "on" : "off",
                  info("gpu_occlusion_probes"), info("gpu_occlusion_early_probes"), info("gpu_occlusion_switches"));
    text += buf;
  }
  if (info("cell_entries") > 0.0) {
    std::snprintf(buf, sizeof(buf),
                  "cells:           %.0f entered: %.0f uploaded ahead, %.0f partly, %.0f stalls (read in the frame); "
                  "slowest load in a frame %.2f ms, uploads ahead %.1f ms in all\n",
                  info("cell_entries"), info("cells_entered_uploaded"), info("cells_entered_partly_uploaded"),
                  info("stall_frames"), info("cell_load_ms_max"), info("upload_ahead_ms_total"));
    text += buf;
  }
  return text;
}

}  // namespace farfield::eval
