#include "farfield/gpu/gpu_timer.h"

#include <epoxy/gl.h>

#include <algorithm>

namespace farfield::gpu {

GpuTimer::GpuTimer() { glCreateQueries(GL_TIME_ELAPSED, 1, &query_); }

GpuTimer::~GpuTimer() {
  if (query_) glDeleteQueries(1, &query_);
}

void GpuTimer::begin() {
  since_begin_.restart();
  glBeginQuery(GL_TIME_ELAPSED, query_);
}

void GpuTimer::end() {
  glEndQuery(GL_TIME_ELAPSED);
  ended_ = true;
}

double GpuTimer::elapsedMs() const {
  // A query that never ran has no result; asking for it would be a GL error.
  if (!ended_) return 0.0;
  GLuint64 ns = 0;
  glGetQueryObjectui64v(query_, GL_QUERY_RESULT, &ns);
  // llvmpipe records a query's start per rasterizer thread; a thread that got no work between begin and end
  // reports its end time minus zero (the time since boot). The wall time bounds the real figure.
  return std::min(double(ns) * 1e-6, since_begin_.milliseconds());
}

}  // namespace farfield::gpu
