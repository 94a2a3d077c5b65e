// What a frame asks of OpenGL, counted at every call: GL calls, draw calls, compute dispatches, bytes sent from the
// CPU, CPU-GPU synchronisations, and the time spent inside GL calls (the driver's). All but the last do not depend
// on the machine, so they say on llvmpipe what a frame will cost on a GPU: a frame that issues 200,000 draw calls or
// waits once for the GPU is slow everywhere (DESIGN.md, "The GPU-driven frame"). A frame's own CPU time, the time in
// Farfield's own code, is its wall time less the driver's and less the measurement's (GlMeasurement).
//
// FF_GL_PROFILE=1 in the environment also times every call per entry point and prints the totals at exit (a
// developer's view of where a frame's driver time goes; it slows every call a little).
//
// How: libepoxy calls OpenGL through one public function pointer per entry point (epoxy_glDrawElements, ...).
// installGlCounters() points those Farfield calls at counting wrappers that call the driver's entry point, taken from
// eglGetProcAddress (which, under libglvnd, dispatches to whatever context is current, EGL or GLX). Counters are per
// thread, so a frame on the render thread is not mixed with a bake worker's GL work.
//
// What counts as what:
//   - a synchronisation is a call that makes the CPU wait for the GPU: glFinish, glReadPixels and glGetTextureImage
//     into client memory, glGetNamedBufferSubData, a map of a buffer for reading, glClientWaitSync that had to wait,
//     and a query result asked for before it was available;
//   - uploaded bytes are the buffer and texture data and the uniform values sent from client memory;
//   - driver time is the time inside every GL call, read from the time-stamp counter (a few nanoseconds a read, two
//     reads a call: about 1 ms per 50,000 calls); on llvmpipe the rasterizer's own work (vertex shading, binning,
//     compute shaders, the flushes a barrier makes) runs inside the calls on the calling thread.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace farfield::gpu {

struct GlCounters {
  uint64_t calls = 0;         // GL entry points called
  uint64_t draw_calls = 0;    // glDraw* and glMultiDraw* calls (a multi-draw counts once)
  uint64_t dispatches = 0;    // glDispatchCompute*
  uint64_t syncs = 0;         // calls that waited (or may have waited) for the GPU
  uint64_t upload_bytes = 0;  // buffer, texture and uniform data sent from client memory
  double driver_ms = 0.0;     // time inside GL calls
  double measure_ms = 0.0;    // time inside GlMeasurement scopes (their GL calls are not counted)

  // The counts and times since `o` (an earlier read); times are never negative (see the .cpp).
  GlCounters& operator-=(const GlCounters& o);
  friend GlCounters operator-(GlCounters a, const GlCounters& b) { return a -= b; }
};

// Points Farfield's GL entry points at the counting wrappers; needs a current context, an EGL one, or with
// `window_context` a GLFW window's (GLX: a viewer's process may have no other). Idempotent and thread-safe; the first
// call with a context current installs for the whole process, a call without one decides nothing. Returns false (and
// counts nothing) where the driver's entry points cannot be resolved; FF_GL_COUNTERS=0 in the environment turns it off.
bool installGlCounters(bool window_context = false);
bool glCountersInstalled();
// The calling thread's totals since installation (all zero before it).
GlCounters glCounters();

// A scope whose GL calls are the measurement's, not the frame's (the harness's glFinish that ends a timed frame, a
// timer's own waits): they are not counted, and the scope's whole duration goes to measure_ms. Nests.
class GlMeasurement {
 public:
  GlMeasurement();
  ~GlMeasurement();
  GlMeasurement(const GlMeasurement&) = delete;
  GlMeasurement& operator=(const GlMeasurement&) = delete;

 private:
  int64_t start_ns_;
};

// The entry points that are counted (for the test that every gl* call in Farfield's sources is among them).
std::vector<std::string> countedGlFunctions();

}  // namespace farfield::gpu
