#include "farfield/eval/frame_runner.h"

#include <string>

#include "farfield/core/error.h"
#include "farfield/core/timer.h"

namespace farfield::eval {

Camera pathCamera(const gen::CameraPath& path, size_t i, int width, int height, float near_plane,
                  float far_plane) {
  if (i >= path.frames.size())
    throw Error("camera path", "frame " + std::to_string(i) + " requested but the path has " +
                                   std::to_string(path.frames.size()) + " frames");
  Camera camera = path.camera(i, width, height, near_plane, far_plane);
  const std::string what = "camera path frame " + std::to_string(i);
  camera.validate(what.c_str());
  return camera;
}

FrameRunner::FrameRunner(gpu::Renderer& renderer, gpu::RenderTarget& target)
    : renderer_(renderer), target_(target), finish_target_(1, 1) {}

FrameRecord FrameRunner::run(Mode& mode, const Camera& camera, size_t path_frame) {
  FrameRecord record;
  record.path_frame = path_frame;
  gpu::FrameStats stats;

  Stopwatch clock;
  FrameContext frame(camera, path_frame, renderer_, target_, items_, &timer_);
  mode.frame(frame);
  if (!frame.drewPasses()) {
    // The common case: one pass. Renderer::render clears, draws and waits (glFinish), so the frame is complete;
    // its GPU time covers the clear and the draws.
    stats = renderer_.render(camera, frame.mainItems(), target_);
  } else {
    // The mode drew passes of its own onto the cleared target (FrameContext started timer_ with the first one);
    // the main pass goes on top. Nothing has waited for the GPU yet. Only the gpu module calls OpenGL, and its
    // public way to wait is Renderer::render, which clears its target first: render nothing into a 1x1 target of
    // our own, whose glFinish also waits for every command issued before it (the frame's passes and any impostor
    // updates into other targets).
    stats = frame.passStats();
    if (!frame.mainItems().empty()) {
      const gpu::FrameStats main = renderer_.draw(camera, frame.mainItems(), target_);
      stats.triangles += main.triangles;
      stats.draw_calls += main.draw_calls;
      stats.objects += main.objects;
    }
    timer_.end();
    Camera tiny = camera;
    tiny.width = tiny.height = 1;
    renderer_.render(tiny, {}, finish_target_);
    stats.gpu_ms = timer_.elapsedMs();
  }
  record.wall_ms = clock.milliseconds();
  record.gpu_ms = stats.gpu_ms;
  record.triangles = stats.triangles;
  record.draw_calls = stats.draw_calls;
  record.objects = stats.objects;
  return record;
}

}  // namespace farfield::eval
