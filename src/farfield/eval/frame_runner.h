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
  uint32_t draw_calls = 0;
  uint32_t objects = 0;   // objects drawn (distinct per pass; see FrameContext::addStats)
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

// Fills a run's frame statistics from its frames: wall and GPU summaries (frame_stats.h) and the mean triangles,
// draw calls and objects. R is any result with `frames`, `wall`, `gpu` and the three means (bench's ModeResult,
// walk's WalkResult).
template <class R>
void summarizeFrames(R& result) {
  std::vector<double> wall, gpu;
  wall.reserve(result.frames.size());
  gpu.reserve(result.frames.size());
  for (const FrameRecord& f : result.frames) {
    wall.push_back(f.wall_ms);
    gpu.push_back(f.gpu_ms);
  }
  result.wall = summarize(wall);
  result.gpu = summarize(gpu);
  result.mean_triangles = meanOf(result.frames, [](const FrameRecord& f) { return f.triangles; });
  result.mean_draw_calls = meanOf(result.frames, [](const FrameRecord& f) { return f.draw_calls; });
  result.mean_objects = meanOf(result.frames, [](const FrameRecord& f) { return f.objects; });
}

class FrameRunner {
 public:
  // Needs a current context; renderer and target must outlive the runner.
  FrameRunner(gpu::Renderer& renderer, gpu::RenderTarget& target);

  // Renders one frame of the mode into the target and waits for it. The wall time covers Mode::frame() (CPU
  // selection), the clear, every pass the mode drew, the main pass and glFinish. Readback is not part of it.
  FrameRecord run(Mode& mode, const Camera& camera, size_t path_frame);

 private:
  gpu::Renderer& renderer_;
  gpu::RenderTarget& target_;
  gpu::RenderTarget finish_target_;  // 1x1, see run()
  gpu::GpuTimer timer_;              // GPU time of frames whose mode draws passes itself
  std::vector<gpu::DrawItem> items_;
};

}  // namespace farfield::eval
