// The timed frame: one mode, one camera, one render target. Shared by `farfield walk` and `farfield bench` so that
// every mode and every command measures a frame the same way.
#pragma once

#include <cstdint>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/eval/mode.h"
#include "farfield/eval/frame_stats.h"
#include "farfield/gen/camera_path.h"
#include "farfield/gpu/gpu_timer.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/renderer.h"

namespace farfield::eval {

// One measured frame.
struct FrameRecord {
  size_t path_frame = 0;  // index into the camera path
  double wall_ms = 0.0;   // from Mode::frame() to glFinish, CPU wall clock
  double gpu_ms = 0.0;    // gpu::GpuTimer from the clear through the last pass (the CPU clock to glFinish on llvmpipe)
  uint64_t triangles = 0;
  uint32_t draw_calls = 0;  // draw calls issued (every glDraw*/glMultiDraw* of the frame where GL calls are counted)
  uint32_t objects = 0;   // objects drawn (distinct per pass; see FrameContext::addStats)
  // What the frame asked of OpenGL (gpu/gl_counters.h; zero where GL calls are not counted), the harness's own
  // waits and timer queries left out:
  double cpu_ms = 0.0;        // Farfield's own CPU time: wall time less the time inside GL calls that do or wait
                              // for GPU work (driver_ms) and less the harness's measurement
  double driver_ms = 0.0;     // time inside those GL calls (on llvmpipe: its vertex work, compute shaders, waits)
  uint64_t gl_calls = 0;
  uint32_t dispatches = 0;    // compute dispatches
  uint64_t upload_bytes = 0;  // buffer, texture and uniform data sent from the CPU
  uint32_t syncs = 0;         // CPU-GPU synchronisations (calls that waited for the GPU)
  bool counted = false;       // whether the GL counters above were installed
  // A governed mode's decision (Mode::governance): its level (-1: no governor), the cost model's prediction and its
  // correction, and the error bound the frame kept as a multiple of the promised one.
  int governor_level = -1;
  double predicted_ms = 0.0;
  double corrected_ms = 0.0;
  double bound_scale = 1.0;
  // Whether the frame drew an impostor (Mode::drewImpostors): 1 or 0; -1 for a mode that draws none by design.
  int impostors = -1;
};

// The camera of path frame i at the given size; throws farfield::Error naming the frame when it is unusable
// (eye == look-at, up parallel to the view, bad field of view) or when i is out of range.
Camera pathCamera(const gen::CameraPath& path, size_t i, int width, int height, float near_plane = 0.5f,
                  float far_plane = 20000.0f);

// Mean of a per-frame quantity, 0 for no frames.
template <class F>
double meanOf(const std::vector<FrameRecord>& frames, F&& field) {
  if (frames.empty()) return 0.0;
  double sum = 0.0;
  for (const FrameRecord& f : frames) sum += double(field(f));
  return sum / double(frames.size());
}

// What a run's frames asked of OpenGL (FrameRecord's counters): means and maxima over the frames.
struct CallSummary {
  bool counted = false;  // every frame was counted (gpu/gl_counters.h installed)
  double gl_calls_mean = 0.0, dispatches_mean = 0.0, upload_bytes_mean = 0.0, syncs_mean = 0.0;
  double driver_ms_median = 0.0;
  uint64_t gl_calls_max = 0, upload_bytes_max = 0;
  uint32_t draw_calls_max = 0, syncs_max = 0;
  size_t frames_with_syncs = 0;
};
CallSummary summarizeCalls(const std::vector<FrameRecord>& frames);

// Fills a run's frame statistics from its frames: wall, GPU and own CPU summaries (frame_stats.h), the mean
// triangles, draw calls and objects, and the GL call summary. R is any result with `frames`, `wall`, `gpu`, `cpu`,
// the three means and `calls` (bench's ModeResult, walk's WalkResult).
template <class R>
void summarizeFrames(R& result) {
  std::vector<double> wall, gpu, cpu;
  wall.reserve(result.frames.size());
  gpu.reserve(result.frames.size());
  cpu.reserve(result.frames.size());
  for (const FrameRecord& f : result.frames) {
    wall.push_back(f.wall_ms);
    gpu.push_back(f.gpu_ms);
    cpu.push_back(f.cpu_ms);
  }
  result.wall = summarize(wall);
  result.gpu = summarize(gpu);
  result.cpu = summarize(cpu);
  result.mean_triangles = meanOf(result.frames, [](const FrameRecord& f) { return f.triangles; });
  result.mean_draw_calls = meanOf(result.frames, [](const FrameRecord& f) { return f.draw_calls; });
  result.mean_objects = meanOf(result.frames, [](const FrameRecord& f) { return f.objects; });
  result.calls = summarizeCalls(result.frames);
}

class FrameRunner {
 public:
  // Needs a current context; renderer and target must outlive the runner.
  FrameRunner(gpu::Renderer& renderer, gpu::RenderTarget& target);

  // Renders one frame of the mode into the target and waits for it. The wall time covers Mode::frame() (CPU
  // selection), the clear, every pass the mode drew, the main pass and glFinish. Readback is not part of it. The
  // wait at the end is the measurement's (not counted among the frame's synchronisations); after it, statistics the
  // mode reads from the GPU late (Mode::lateFrameStats) complete the record.
  FrameRecord run(Mode& mode, const Camera& camera, size_t path_frame);

 private:
  gpu::Renderer& renderer_;
  gpu::RenderTarget& target_;
  gpu::RenderTarget finish_target_;  // 1x1, see run()
  gpu::GpuTimer timer_;              // GPU time of frames whose mode draws passes itself
  std::vector<gpu::DrawItem> items_;
};

}  // namespace farfield::eval
