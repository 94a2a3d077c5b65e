#include "farfield/gpu/gpu_timer.h"

#include <epoxy/gl.h>

#include <algorithm>
#include <string>

#include "farfield/gpu/gl_counters.h"

namespace farfield::gpu {

bool currentRendererIsSoftware() {
  const auto* name = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  const std::string renderer = name ? name : "";
  return renderer.find("llvmpipe") != std::string::npos || renderer.find("softpipe") != std::string::npos ||
         renderer.find("swrast") != std::string::npos;
}

GpuTimer::GpuTimer(Source source) : source_(source) {
  if (source_ == Source::Auto) source_ = currentRendererIsSoftware() ? Source::CpuClock : Source::Query;
  if (source_ == Source::Query) glCreateQueries(GL_TIME_ELAPSED, 1, &query_);
}

GpuTimer::~GpuTimer() {
  if (query_) glDeleteQueries(1, &query_);
}

void GpuTimer::begin() {
  if (source_ == Source::CpuClock) {
    // Earlier work (uploads, another pass) must not be counted: a software rasterizer would do it inside our span.
    // The wait is the measurement's, not the frame's (gl_counters.h).
    GlMeasurement measurement;
    glFinish();
    since_begin_.restart();
    return;
  }
  since_begin_.restart();
  glBeginQuery(GL_TIME_ELAPSED, query_);
}

void GpuTimer::end() {
  if (source_ == Source::CpuClock) {
    GlMeasurement measurement;
    glFinish();  // the work is done when the rasterizer threads are
    cpu_clock_ms_ = since_begin_.milliseconds();
  } else {
    glEndQuery(GL_TIME_ELAPSED);
  }
  ended_ = true;
}

bool GpuTimer::ready() const {
  if (!ended_ || source_ == Source::CpuClock) return true;
  GLuint available = 0;
  glGetQueryObjectuiv(query_, GL_QUERY_RESULT_AVAILABLE, &available);
  return available != 0;
}

double GpuTimer::elapsedMs() const {
  // A query that never ran has no result; asking for it would be a GL error.
  if (!ended_) return 0.0;
  if (source_ == Source::CpuClock) return cpu_clock_ms_;
  GLuint64 ns = 0;
  glGetQueryObjectui64v(query_, GL_QUERY_RESULT, &ns);
  // llvmpipe records a query's start per rasterizer thread; a thread that got no work between begin and end
  // reports its end time minus zero (the time since boot). The wall time bounds the real figure.
  return std::min(double(ns) * 1e-6, since_begin_.milliseconds());
}

}  // namespace farfield::gpu
