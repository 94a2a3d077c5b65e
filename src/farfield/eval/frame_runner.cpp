#include "farfield/eval/frame_runner.h"

#include <algorithm>
#include <optional>
#include <string>

#include "farfield/core/error.h"
#include "farfield/core/timer.h"
#include "farfield/gpu/gl_counters.h"

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

CallSummary summarizeCalls(const std::vector<FrameRecord>& frames) {
  CallSummary c;
  c.counted = !frames.empty();
  std::vector<double> driver;
  for (const FrameRecord& f : frames) {
    c.counted = c.counted && f.counted;
    driver.push_back(f.driver_ms);
    c.gl_calls_max = std::max(c.gl_calls_max, f.gl_calls);
    c.upload_bytes_max = std::max(c.upload_bytes_max, f.upload_bytes);
    c.draw_calls_max = std::max(c.draw_calls_max, f.draw_calls);
    c.syncs_max = std::max(c.syncs_max, f.syncs);
    c.frames_with_syncs += f.syncs > 0;
  }
  c.gl_calls_mean = meanOf(frames, [](const FrameRecord& f) { return f.gl_calls; });
  c.dispatches_mean = meanOf(frames, [](const FrameRecord& f) { return f.dispatches; });
  c.upload_bytes_mean = meanOf(frames, [](const FrameRecord& f) { return f.upload_bytes; });
  c.syncs_mean = meanOf(frames, [](const FrameRecord& f) { return f.syncs; });
  c.driver_ms_median = summarize(driver).median;
  return c;
}

FrameRunner::FrameRunner(gpu::Renderer& renderer, gpu::RenderTarget& target)
    : renderer_(renderer), target_(target), finish_target_(1, 1) {
  gpu::installGlCounters();
}

FrameRecord FrameRunner::run(Mode& mode, const Camera& camera, size_t path_frame) {
  FrameRecord record;
  record.path_frame = path_frame;
  gpu::FrameStats stats;

  const gpu::GlCounters before = gpu::glCounters();
  Stopwatch clock;
  FrameContext frame(camera, path_frame, renderer_, target_, items_, &timer_);
  mode.frame(frame);
  // The main pass: on the target the mode's passes drew (FrameContext started timer_ with the first one), else on the
  // target cleared now (the timer started with the clear, as Renderer::render's GPU time covers it); the wait below.
  stats = frame.drawMainPass();
  {
    // The wait for the frame is the measurement's. Only the gpu module calls OpenGL, and its public way to wait is
    // Renderer::render, which clears its target first: render nothing into a 1x1 target of our own, whose glFinish
    // also waits for every command issued before it (the frame's passes and any updates into other targets).
    gpu::GlMeasurement measurement;
    timer_.end();
    Camera tiny = camera;
    tiny.width = tiny.height = 1;
    renderer_.render(tiny, {}, finish_target_);
    stats.gpu_ms = std::min(timer_.elapsedMs(), clock.milliseconds());
    record.wall_ms = clock.milliseconds();
    if (const std::optional<gpu::FrameStats> late = mode.lateFrameStats(path_frame)) {
      stats.triangles += late->triangles;
      stats.objects += late->objects;
    }
  }
  const gpu::GlCounters used = gpu::glCounters() - before;
  record.gpu_ms = stats.gpu_ms;
  record.triangles = stats.triangles;
  record.draw_calls = stats.draw_calls;
  record.objects = stats.objects;
  record.counted = gpu::glCountersInstalled();
  if (record.counted) {
    record.draw_calls = uint32_t(used.draw_calls);
    record.gl_calls = used.calls;
    record.dispatches = uint32_t(used.dispatches);
    record.upload_bytes = used.upload_bytes;
    record.syncs = uint32_t(used.syncs);
    record.driver_ms = used.driver_ms;
  }
  record.cpu_ms = std::max(0.0, record.wall_ms - used.driver_ms - used.measure_ms);
  mode.frameMeasured(path_frame, record.wall_ms);
  if (const std::optional<FrameGovernance> g = mode.governance(path_frame)) {
    record.governor_level = int(g->level);
    record.predicted_ms = g->predicted_ms;
    record.corrected_ms = g->corrected_ms;
    record.bound_scale = g->bound_scale;
  }
  if (const std::optional<bool> drew = mode.drewImpostors()) record.impostors = *drew ? 1 : 0;
  return record;
}

}  // namespace farfield::eval
