#include "farfield/gpu/gl_counters.h"

#include <epoxy/egl.h>
#include <epoxy/gl.h>

#include <algorithm>
#include <atomic>
#if defined(__x86_64__) || defined(__i386__)
#include <x86intrin.h>
#endif
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <tuple>
#include <type_traits>

#include "farfield/gpu/gl_barrier_check_hooks.h"

namespace farfield::gpu {

GlCounters& GlCounters::operator-=(const GlCounters& o) {
  calls -= o.calls;
  draw_calls -= o.draw_calls;
  dispatches -= o.dispatches;
  syncs -= o.syncs;
  upload_bytes -= o.upload_bytes;
  // Times are tick counts converted with a tick rate estimated anew at each read: two reads of an unchanged count may
  // differ by a few nanoseconds either way, and no time between two reads is negative.
  driver_ms = std::max(0.0, driver_ms - o.driver_ms);
  measure_ms = std::max(0.0, measure_ms - o.measure_ms);
  return *this;
}

namespace {

struct ThreadState {
  GlCounters counters;    // driver_ms from driver_ticks when read
  uint64_t driver_ticks = 0;
  int paused = 0;  // inside GlMeasurement scopes
};
thread_local ThreadState t_state;
std::atomic<bool> g_installed{false};
bool g_profile = false;  // FF_GL_PROFILE: every call timed per entry point, printed at exit

int64_t nowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// The clock of driver time: the time-stamp counter where there is one (a few nanoseconds a read; every GL call reads
// it twice), calibrated against the steady clock between installation and each reading of the counters.
#if defined(__x86_64__) || defined(__i386__)
inline uint64_t ticks() { return __rdtsc(); }
#else
inline uint64_t ticks() { return uint64_t(nowNs()); }
#endif
uint64_t g_tick0 = 0;
int64_t g_ns0 = 0;

double ticksToMs(uint64_t t) {
  const uint64_t dt = ticks() - g_tick0;
  const int64_t dns = nowNs() - g_ns0;
  const double ns_per_tick = dt > 0 && dns > 0 ? double(dns) / double(dt) : 1.0;
  return double(t) * ns_per_tick * 1e-6;
}

// What a call counts as besides a GL call (every call is timed as driver time).
enum class Kind {
  Plain,     // state, objects, queries, uploads
  Draw,      // a draw call
  Dispatch,  // a compute dispatch
  Work,      // GPU work that a software rasterizer does inside the call (clears, blits, copies, barriers, fences)
  Sync,      // always waits for the GPU
  Extra,     // the extra function decides whether it waited
};

// The driver's entry points used by the extra functions to look at state without being counted.
PFNGLGETINTEGERVPROC g_get_integer = nullptr;
PFNGLGETQUERYOBJECTIVPROC g_get_query_iv = nullptr;

// The barrier check's view of an entry point (gl_barrier_check.h): none, unless specialised below.
template <auto Slot>
struct BarrierCheck {
  static constexpr bool active = false;
};
#define FF_BARRIER_CHECK(fn, ...)                 \
  template <>                                     \
  struct BarrierCheck<&epoxy_##fn> {              \
    static constexpr bool active = true;          \
    template <class... A>                         \
    static void check([[maybe_unused]] A... a) {  \
      namespace bc = barrier_check;               \
      __VA_ARGS__;                                \
    }                                             \
  };
// (The arguments by position: std::get<N>(std::tie(a...)).)
#define FF_ARG(n) std::get<n>(std::tie(a...))
FF_BARRIER_CHECK(glShaderSource, bc::shaderSource(FF_ARG(0), FF_ARG(1), FF_ARG(2), FF_ARG(3)))
FF_BARRIER_CHECK(glAttachShader, bc::attachShader(FF_ARG(0), FF_ARG(1)))
FF_BARRIER_CHECK(glDeleteProgram, bc::deleteProgram(FF_ARG(0)))
FF_BARRIER_CHECK(glUseProgram, bc::useProgram(FF_ARG(0)))
FF_BARRIER_CHECK(glBindBufferBase, bc::bindBufferBase(FF_ARG(0), FF_ARG(1), FF_ARG(2)))
FF_BARRIER_CHECK(glBindBufferRange, bc::bindBufferBase(FF_ARG(0), FF_ARG(1), FF_ARG(2)))
FF_BARRIER_CHECK(glBindBuffer, bc::bindBuffer(FF_ARG(0), FF_ARG(1)))
FF_BARRIER_CHECK(glBindTextureUnit, bc::bindTextureUnit(FF_ARG(0), FF_ARG(1)))
FF_BARRIER_CHECK(glBindImageTexture, bc::bindImageTexture(FF_ARG(0), FF_ARG(1)))
FF_BARRIER_CHECK(glDeleteBuffers, bc::deleteBuffers(FF_ARG(0), FF_ARG(1)))
FF_BARRIER_CHECK(glDeleteTextures, bc::deleteTextures(FF_ARG(0), FF_ARG(1)))
FF_BARRIER_CHECK(glMemoryBarrier, bc::memoryBarrier(FF_ARG(0)))
FF_BARRIER_CHECK(glDispatchCompute, bc::dispatch("glDispatchCompute", false))
FF_BARRIER_CHECK(glDispatchComputeIndirect, bc::dispatch("glDispatchComputeIndirect", true))
FF_BARRIER_CHECK(glDrawArrays, bc::draw("glDrawArrays", false, false))
FF_BARRIER_CHECK(glDrawArraysInstanced, bc::draw("glDrawArraysInstanced", false, false))
FF_BARRIER_CHECK(glDrawElements, bc::draw("glDrawElements", false, false))
FF_BARRIER_CHECK(glDrawElementsInstanced, bc::draw("glDrawElementsInstanced", false, false))
FF_BARRIER_CHECK(glDrawElementsBaseVertex, bc::draw("glDrawElementsBaseVertex", false, false))
FF_BARRIER_CHECK(glDrawElementsInstancedBaseVertexBaseInstance,
                 bc::draw("glDrawElementsInstancedBaseVertexBaseInstance", false, false))
FF_BARRIER_CHECK(glMultiDrawElementsIndirect, bc::draw("glMultiDrawElementsIndirect", true, false);
                 bc::indexedIndirect("glMultiDrawElementsIndirect", FF_ARG(1), FF_ARG(2), FF_ARG(3), FF_ARG(4), -1))
FF_BARRIER_CHECK(glMultiDrawArraysIndirect, bc::draw("glMultiDrawArraysIndirect", true, false))
FF_BARRIER_CHECK(glMultiDrawElementsIndirectCount, bc::draw("glMultiDrawElementsIndirectCount", true, true);
                 bc::indexedIndirect("glMultiDrawElementsIndirectCount", FF_ARG(1), FF_ARG(2), FF_ARG(4), FF_ARG(5),
                                     FF_ARG(3)))
FF_BARRIER_CHECK(glMultiDrawElementsIndirectCountARB, bc::draw("glMultiDrawElementsIndirectCountARB", true, true);
                 bc::indexedIndirect("glMultiDrawElementsIndirectCountARB", FF_ARG(1), FF_ARG(2), FF_ARG(4),
                                     FF_ARG(5), FF_ARG(3)))
FF_BARRIER_CHECK(glCopyNamedBufferSubData, bc::bufferUpdate("glCopyNamedBufferSubData", FF_ARG(0), true);
                 bc::bufferUpdate("glCopyNamedBufferSubData", FF_ARG(1), false))
FF_BARRIER_CHECK(glClearNamedBufferSubData, bc::bufferUpdate("glClearNamedBufferSubData", FF_ARG(0), false))
FF_BARRIER_CHECK(glClearNamedBufferData, bc::bufferUpdate("glClearNamedBufferData", FF_ARG(0), false))
FF_BARRIER_CHECK(glNamedBufferSubData, bc::bufferUpdate("glNamedBufferSubData", FF_ARG(0), false))
FF_BARRIER_CHECK(glGetNamedBufferSubData, bc::bufferUpdate("glGetNamedBufferSubData", FF_ARG(0), true))
FF_BARRIER_CHECK(glNamedBufferStorage, bc::bufferStorage(FF_ARG(0), FF_ARG(1), FF_ARG(2) != nullptr))
FF_BARRIER_CHECK(glNamedBufferData, bc::bufferStorage(FF_ARG(0), FF_ARG(1), FF_ARG(2) != nullptr))
FF_BARRIER_CHECK(glVertexArrayElementBuffer, bc::vertexArrayElementBuffer(FF_ARG(0), FF_ARG(1)))
FF_BARRIER_CHECK(glBindVertexArray, bc::bindVertexArray(FF_ARG(0)))
FF_BARRIER_CHECK(glNamedFramebufferTexture, bc::framebufferTexture(FF_ARG(0), FF_ARG(1), FF_ARG(2)))
FF_BARRIER_CHECK(glNamedFramebufferTextureLayer, bc::framebufferTexture(FF_ARG(0), FF_ARG(1), FF_ARG(2)))
FF_BARRIER_CHECK(glBindFramebuffer, bc::bindFramebuffer(FF_ARG(0), FF_ARG(1)))
FF_BARRIER_CHECK(glDeleteFramebuffers, bc::deleteFramebuffers(FF_ARG(0), FF_ARG(1)))
FF_BARRIER_CHECK(glMapNamedBufferRange, bc::mapBuffer(FF_ARG(0), FF_ARG(3)))
FF_BARRIER_CHECK(glGetTextureImage, bc::textureUpdate("glGetTextureImage", FF_ARG(0), true))
FF_BARRIER_CHECK(glGetTextureSubImage, bc::textureUpdate("glGetTextureSubImage", FF_ARG(0), true))
FF_BARRIER_CHECK(glClearTexImage, bc::textureUpdate("glClearTexImage", FF_ARG(0), false))
FF_BARRIER_CHECK(glTextureSubImage2D, bc::textureUpdate("glTextureSubImage2D", FF_ARG(0), false))
FF_BARRIER_CHECK(glTextureSubImage3D, bc::textureUpdate("glTextureSubImage3D", FF_ARG(0), false))
#undef FF_ARG
#undef FF_BARRIER_CHECK

// The wrapper of one entry point: Slot is the address of libepoxy's function pointer (epoxy_glDrawElements, ...).
// Extra, when not void, is a function object called with the counters and the call's arguments before the call.
template <auto Slot, Kind K, typename Extra = void>
struct Hook;

template <typename R, typename... A, R (**Slot)(A...), Kind K, typename Extra>
struct Hook<Slot, K, Extra> {
  using Fn = R (*)(A...);
  static inline Fn real = nullptr;
  static inline std::atomic<uint64_t> profile_calls{0}, profile_ns{0};

  struct Profiled {
    int64_t start = g_profile ? nowNs() : 0;
    ~Profiled() {
      if (!g_profile) return;
      ++profile_calls;
      profile_ns += uint64_t(nowNs() - start);
    }
  };

  static R call(A... args) {
    // The wrapper's own bookkeeping is timed with the call, so that it is the measurement's, not Farfield's code.
    const uint64_t start = ticks();
    Profiled profiled;
    // The barrier check follows every call, the measurement's too (its reads need barriers as much as a frame's).
    if constexpr (BarrierCheck<Slot>::active)
      if (barrier_check::on()) BarrierCheck<Slot>::check(args...);
    ThreadState& t = t_state;
    if (t.paused) return real(args...);
    GlCounters& c = t.counters;
    ++c.calls;
    if constexpr (K == Kind::Draw) ++c.draw_calls;
    if constexpr (K == Kind::Dispatch) ++c.dispatches;
    if constexpr (K == Kind::Sync) ++c.syncs;
    if constexpr (!std::is_void_v<Extra>) Extra{}(c, args...);
    struct Timed {
      uint64_t& total;
      uint64_t start;
      ~Timed() { total += ticks() - start; }
    } timed{t.driver_ticks, start};
    return real(args...);
  }
  static void install(void* proc) {
    real = reinterpret_cast<Fn>(proc);
    *Slot = &call;
  }
  static void report(const char* name) {
    if (profile_calls)
      std::fprintf(stderr, "gl profile: %-44s %12llu calls %12.3f ms\n", name,
                   static_cast<unsigned long long>(profile_calls.load()), double(profile_ns.load()) * 1e-6);
  }
};

// ---- bytes and conditional waits -------------------------------------------------------------------------------

uint64_t pixelBytes(GLenum format, GLenum type) {
  uint64_t components = 4;
  switch (format) {
    case GL_RED: case GL_RED_INTEGER: case GL_DEPTH_COMPONENT: case GL_STENCIL_INDEX: components = 1; break;
    case GL_RG: case GL_RG_INTEGER: case GL_DEPTH_STENCIL: components = 2; break;
    case GL_RGB: case GL_RGB_INTEGER: case GL_BGR: components = 3; break;
    default: components = 4;
  }
  switch (type) {
    case GL_UNSIGNED_BYTE: case GL_BYTE: return components;
    case GL_UNSIGNED_SHORT: case GL_SHORT: case GL_HALF_FLOAT: return 2 * components;
    case GL_UNSIGNED_INT_24_8: case GL_UNSIGNED_INT_8_8_8_8_REV: return 4;
    default: return 4 * components;  // GL_FLOAT, GL_INT, GL_UNSIGNED_INT
  }
}

bool bound(GLenum binding) {
  GLint buffer = 0;
  if (g_get_integer) g_get_integer(binding, &buffer);
  return buffer != 0;
}

void bufferStorage(GlCounters& c, GLuint, GLsizeiptr size, const void* data, GLbitfield) {
  if (data) c.upload_bytes += uint64_t(size);
}
void bufferData(GlCounters& c, GLuint, GLsizeiptr size, const void* data, GLenum) {
  if (data) c.upload_bytes += uint64_t(size);
}
void bufferDataTarget(GlCounters& c, GLenum, GLsizeiptr size, const void* data, GLenum) {
  if (data) c.upload_bytes += uint64_t(size);
}
void bufferSubData(GlCounters& c, GLuint, GLintptr, GLsizeiptr size, const void*) { c.upload_bytes += uint64_t(size); }
void bufferSubDataTarget(GlCounters& c, GLenum, GLintptr, GLsizeiptr size, const void*) {
  c.upload_bytes += uint64_t(size);
}
void textureSubImage2D(GlCounters& c, GLuint, GLint, GLint, GLint, GLsizei w, GLsizei h, GLenum format, GLenum type,
                       const void*) {
  if (!bound(GL_PIXEL_UNPACK_BUFFER_BINDING)) c.upload_bytes += uint64_t(w) * uint64_t(h) * pixelBytes(format, type);
}
void textureSubImage3D(GlCounters& c, GLuint, GLint, GLint, GLint, GLint, GLsizei w, GLsizei h, GLsizei d,
                       GLenum format, GLenum type, const void*) {
  if (!bound(GL_PIXEL_UNPACK_BUFFER_BINDING))
    c.upload_bytes += uint64_t(w) * uint64_t(h) * uint64_t(d) * pixelBytes(format, type);
}

// Reads into client memory wait for the GPU; into a pixel pack buffer they do not.
void readPixels(GlCounters& c, GLint, GLint, GLsizei, GLsizei, GLenum, GLenum, void*) {
  if (!bound(GL_PIXEL_PACK_BUFFER_BINDING)) ++c.syncs;
}
void getTextureImage(GlCounters& c, GLuint, GLint, GLenum, GLenum, GLsizei, void*) {
  if (!bound(GL_PIXEL_PACK_BUFFER_BINDING)) ++c.syncs;
}
void getTextureSubImage(GlCounters& c, GLuint, GLint, GLint, GLint, GLint, GLsizei, GLsizei, GLsizei, GLenum, GLenum,
                        GLsizei, void*) {
  if (!bound(GL_PIXEL_PACK_BUFFER_BINDING)) ++c.syncs;
}
// A query's result asked for before it is available makes the CPU wait for it.
void queryWaits(GlCounters& c, GLuint id, GLenum pname) {
  if (pname != GL_QUERY_RESULT) return;
  GLint available = 1;
  if (g_get_query_iv) g_get_query_iv(id, GL_QUERY_RESULT_AVAILABLE, &available);
  if (!available) ++c.syncs;
}
void queryObjectui64(GlCounters& c, GLuint id, GLenum pname, GLuint64*) { queryWaits(c, id, pname); }
void queryObjecti64(GlCounters& c, GLuint id, GLenum pname, GLint64*) { queryWaits(c, id, pname); }
void queryObjectiv(GlCounters& c, GLuint id, GLenum pname, GLint*) { queryWaits(c, id, pname); }
void queryObjectuiv(GlCounters& c, GLuint id, GLenum pname, GLuint*) { queryWaits(c, id, pname); }
void clientWaitSync(GlCounters& c, GLsync, GLbitfield, GLuint64 timeout) {
  if (timeout > 0) ++c.syncs;
}
void mapBufferRange(GlCounters& c, GLuint, GLintptr, GLsizeiptr, GLbitfield access) {
  if ((access & GL_MAP_READ_BIT) && !(access & GL_MAP_UNSYNCHRONIZED_BIT)) ++c.syncs;
}

// Uniform values: Bytes each; Count is the index of the argument holding their number (-1: one value).
template <uint64_t Bytes, int Count = -1>
struct Uniform {
  template <class... A>
  void operator()(GlCounters& c, A... args) const {
    uint64_t count = 1;
    if constexpr (Count >= 0) count = uint64_t(std::get<Count>(std::tuple<A...>(args...)));
    c.upload_bytes += Bytes * count;
  }
};
// A plain function as the Extra of a hook.
template <auto F>
struct Call {
  template <class... A>
  void operator()(GlCounters& c, A... args) const {
    F(c, args...);
  }
};

struct Entry {
  const char* name;
  void (*install)(void*);
  void (*report)(const char*);
};

// (fn is pasted at once: glDrawArrays and the like are themselves macros of libepoxy's.)
#define FF_ENTRY(name, slot, ...) Entry{name, &Hook<&slot, __VA_ARGS__>::install, &Hook<&slot, __VA_ARGS__>::report}
#define FF_HOOK(fn, kind) FF_ENTRY(#fn, epoxy_##fn, Kind::kind)
#define FF_HOOK_EXTRA(fn, extra) FF_ENTRY(#fn, epoxy_##fn, Kind::Extra, Call<extra>)
#define FF_HOOK_UPLOAD(fn, extra) FF_ENTRY(#fn, epoxy_##fn, Kind::Plain, Call<extra>)
#define FF_HOOK_UNIFORM(fn, ...) FF_ENTRY(#fn, epoxy_##fn, Kind::Plain, Uniform<__VA_ARGS__>)

// Every entry point Farfield calls (tests/gpu/gl_counters_test.cpp checks the sources against this list).
const Entry kEntries[] = {
    // draws and dispatches
    FF_HOOK(glDrawArrays, Draw), FF_HOOK(glDrawArraysInstanced, Draw), FF_HOOK(glDrawElements, Draw),
    FF_HOOK(glDrawElementsInstanced, Draw), FF_HOOK(glDrawElementsBaseVertex, Draw),
    FF_HOOK(glDrawElementsInstancedBaseVertexBaseInstance, Draw), FF_HOOK(glMultiDrawElementsIndirect, Draw),
    FF_HOOK(glMultiDrawElementsIndirectCountARB, Draw), FF_HOOK(glMultiDrawElementsIndirectCount, Draw),
    FF_HOOK(glMultiDrawArraysIndirect, Draw), FF_HOOK(glDispatchCompute, Dispatch),
    FF_HOOK(glDispatchComputeIndirect, Dispatch),
    // GPU work inside the call on a software rasterizer
    FF_HOOK(glClear, Work), FF_HOOK(glClearNamedFramebufferfv, Work), FF_HOOK(glClearNamedFramebufferuiv, Work),
    FF_HOOK(glClearNamedFramebufferiv, Work), FF_HOOK(glBlitNamedFramebuffer, Work),
    FF_HOOK(glGenerateTextureMipmap, Work), FF_HOOK(glCopyNamedBufferSubData, Work),
    FF_HOOK(glClearNamedBufferSubData, Work), FF_HOOK(glClearNamedBufferData, Work), FF_HOOK(glClearTexImage, Work),
    FF_HOOK(glFlush, Work), FF_HOOK(glMemoryBarrier, Work), FF_HOOK(glFenceSync, Work),
    // waits
    FF_HOOK(glFinish, Sync), FF_HOOK(glGetNamedBufferSubData, Sync), FF_HOOK_EXTRA(glReadPixels, readPixels),
    FF_HOOK_EXTRA(glGetTextureImage, getTextureImage), FF_HOOK_EXTRA(glGetTextureSubImage, getTextureSubImage),
    FF_HOOK_EXTRA(glGetQueryObjectui64v, queryObjectui64), FF_HOOK_EXTRA(glGetQueryObjecti64v, queryObjecti64),
    FF_HOOK_EXTRA(glGetQueryObjectiv, queryObjectiv), FF_HOOK_EXTRA(glGetQueryObjectuiv, queryObjectuiv),
    FF_HOOK_EXTRA(glClientWaitSync, clientWaitSync), FF_HOOK_EXTRA(glMapNamedBufferRange, mapBufferRange),
    // uploads
    FF_HOOK_UPLOAD(glNamedBufferStorage, bufferStorage), FF_HOOK_UPLOAD(glNamedBufferData, bufferData),
    FF_HOOK_UPLOAD(glNamedBufferSubData, bufferSubData), FF_HOOK_UPLOAD(glBufferData, bufferDataTarget),
    FF_HOOK_UPLOAD(glBufferSubData, bufferSubDataTarget), FF_HOOK_UPLOAD(glTextureSubImage2D, textureSubImage2D),
    FF_HOOK_UPLOAD(glTextureSubImage3D, textureSubImage3D),
    FF_HOOK_UNIFORM(glUniform1i, 4), FF_HOOK_UNIFORM(glUniform1ui, 4),
    FF_HOOK_UNIFORM(glUniform1f, 4), FF_HOOK_UNIFORM(glUniform2f, 8),
    FF_HOOK_UNIFORM(glUniform2i, 8), FF_HOOK_UNIFORM(glUniform2fv, 8, 1),
    FF_HOOK_UNIFORM(glUniform1iv, 4, 1), FF_HOOK_UNIFORM(glUniform2iv, 8, 1), FF_HOOK_UNIFORM(glUniform1fv, 4, 1),
    FF_HOOK_UNIFORM(glUniform3fv, 12, 1), FF_HOOK_UNIFORM(glUniform4fv, 16, 1),
    FF_HOOK_UNIFORM(glUniform4f, 16), FF_HOOK_UNIFORM(glUniformMatrix3fv, 36, 1),
    FF_HOOK_UNIFORM(glUniformMatrix4fv, 64, 1), FF_HOOK_UNIFORM(glProgramUniform1f, 4),
    FF_HOOK_UNIFORM(glProgramUniform1i, 4),
    FF_HOOK_UNIFORM(glProgramUniform1ui, 4),
    FF_HOOK_UNIFORM(glProgramUniform2i, 8),
    FF_HOOK_UNIFORM(glProgramUniform2f, 8),
    FF_HOOK_UNIFORM(glProgramUniform2iv, 8, 2),
    FF_HOOK_UNIFORM(glProgramUniform3fv, 12, 2),
    FF_HOOK_UNIFORM(glProgramUniform4fv, 16, 2),
    FF_HOOK_UNIFORM(glProgramUniformMatrix4fv, 64, 2),
    // state, objects, queries
    FF_HOOK(glAttachShader, Plain), FF_HOOK(glBeginQuery, Plain), FF_HOOK(glBindBuffer, Plain),
    FF_HOOK(glBindBufferBase, Plain), FF_HOOK(glBindBufferRange, Plain), FF_HOOK(glBindFramebuffer, Plain),
    FF_HOOK(glBindImageTexture, Plain), FF_HOOK(glBindTextureUnit, Plain), FF_HOOK(glBindVertexArray, Plain),
    FF_HOOK(glBlendFuncSeparate, Plain), FF_HOOK(glCheckNamedFramebufferStatus, Plain),
    FF_HOOK(glClearColor, Plain), FF_HOOK(glClearDepth, Plain), FF_HOOK(glClipControl, Plain),
    FF_HOOK(glColorMask, Plain), FF_HOOK(glColorMaski, Plain), FF_HOOK(glCompileShader, Plain),
    FF_HOOK(glCreateBuffers, Plain), FF_HOOK(glCreateFramebuffers, Plain), FF_HOOK(glCreateProgram, Plain),
    FF_HOOK(glCreateQueries, Plain), FF_HOOK(glCreateShader, Plain), FF_HOOK(glCreateTextures, Plain),
    FF_HOOK(glCreateVertexArrays, Plain), FF_HOOK(glCullFace, Plain), FF_HOOK(glDebugMessageCallback, Plain),
    FF_HOOK(glDeleteBuffers, Plain), FF_HOOK(glDeleteFramebuffers, Plain), FF_HOOK(glDeleteProgram, Plain),
    FF_HOOK(glDeleteQueries, Plain), FF_HOOK(glDeleteShader, Plain), FF_HOOK(glDeleteSync, Plain),
    FF_HOOK(glDeleteTextures, Plain), FF_HOOK(glDeleteVertexArrays, Plain), FF_HOOK(glDepthFunc, Plain),
    FF_HOOK(glDepthMask, Plain), FF_HOOK(glDetachShader, Plain), FF_HOOK(glDisable, Plain),
    FF_HOOK(glEnable, Plain), FF_HOOK(glEnableVertexArrayAttrib, Plain), FF_HOOK(glEndQuery, Plain),
    FF_HOOK(glFrontFace, Plain), FF_HOOK(glGetError, Plain), FF_HOOK(glGetFloatv, Plain),
    FF_HOOK(glGetIntegerv, Plain), FF_HOOK(glGetProgramInfoLog, Plain), FF_HOOK(glGetProgramiv, Plain),
    FF_HOOK(glGetShaderInfoLog, Plain), FF_HOOK(glGetShaderiv, Plain), FF_HOOK(glGetString, Plain),
    FF_HOOK(glGetSynciv, Plain), FF_HOOK(glGetUniformLocation, Plain), FF_HOOK(glLinkProgram, Plain),
    FF_HOOK(glNamedFramebufferDrawBuffer, Plain),
    FF_HOOK(glNamedFramebufferDrawBuffers, Plain), FF_HOOK(glNamedFramebufferReadBuffer, Plain),
    FF_HOOK(glNamedFramebufferTexture, Plain), FF_HOOK(glNamedFramebufferTextureLayer, Plain),
    FF_HOOK(glPixelStorei, Plain), FF_HOOK(glPolygonOffset, Plain), FF_HOOK(glQueryCounter, Plain),
    FF_HOOK(glReadBuffer, Plain), FF_HOOK(glShaderSource, Plain), FF_HOOK(glTextureParameterf, Plain),
    FF_HOOK(glTextureParameterfv, Plain), FF_HOOK(glTextureParameteri, Plain), FF_HOOK(glTextureStorage2D, Plain),
    FF_HOOK(glTextureStorage3D, Plain), FF_HOOK(glUnmapNamedBuffer, Plain), FF_HOOK(glUseProgram, Plain),
    FF_HOOK(glVertexArrayAttribBinding, Plain), FF_HOOK(glVertexArrayAttribFormat, Plain),
    FF_HOOK(glVertexArrayAttribIFormat, Plain), FF_HOOK(glVertexArrayBindingDivisor, Plain),
    FF_HOOK(glVertexArrayElementBuffer, Plain), FF_HOOK(glVertexArrayVertexBuffer, Plain),
    FF_HOOK(glViewport, Plain),
};

#undef FF_ENTRY
#undef FF_HOOK
#undef FF_HOOK_EXTRA
#undef FF_HOOK_UPLOAD
#undef FF_HOOK_UNIFORM

}  // namespace

// Points the entry points at the wrappers, with the driver's from eglGetProcAddress; false where it has none.
static bool installEntries() {
  g_get_integer = reinterpret_cast<PFNGLGETINTEGERVPROC>(eglGetProcAddress("glGetIntegerv"));
  g_get_query_iv = reinterpret_cast<PFNGLGETQUERYOBJECTIVPROC>(eglGetProcAddress("glGetQueryObjectiv"));
  if (!g_get_integer || !g_get_query_iv) return false;
  for (const Entry& e : kEntries)
    if (void* proc = reinterpret_cast<void*>(eglGetProcAddress(e.name))) e.install(proc);
  g_tick0 = ticks();
  g_ns0 = nowNs();
  if (const char* env = std::getenv("FF_GL_PROFILE"); env && std::strcmp(env, "0") != 0) {
    g_profile = true;
    std::atexit([] {
      for (const Entry& e : kEntries) e.report(e.name);
    });
  }
  return true;
}

bool installGlCounters(bool window_context) {
  static std::mutex mutex;
  static bool decided = false;  // attempted with a context current, or turned off: never again
  const std::lock_guard lock(mutex);
  if (decided) return g_installed;
  if (const char* env = std::getenv("FF_GL_COUNTERS"); env && std::strcmp(env, "0") == 0) {
    decided = true;
    return false;
  }
  // The entry points resolve through a current context: an EGL one, or a GLFW window's (GLX), whose calls the same
  // pointers reach under libglvnd. Without one nothing is decided, and a later call may install.
  if (!window_context && !eglGetCurrentContext()) return false;
  decided = true;
  g_installed = installEntries();
  return g_installed;
}

bool glCountersInstalled() { return g_installed; }

GlCounters glCounters() {
  GlCounters c = t_state.counters;
  c.driver_ms = ticksToMs(t_state.driver_ticks);
  return c;
}

GlMeasurement::GlMeasurement() : start_ns_(nowNs()) { ++t_state.paused; }

GlMeasurement::~GlMeasurement() {
  if (--t_state.paused == 0) t_state.counters.measure_ms += double(nowNs() - start_ns_) * 1e-6;
}

std::vector<std::string> countedGlFunctions() {
  std::vector<std::string> names;
  for (const Entry& e : kEntries) names.emplace_back(e.name);
  return names;
}

}  // namespace farfield::gpu
