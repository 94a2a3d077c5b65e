#include "farfield/gpu/gl_barrier_check.h"

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include <epoxy/egl.h>

#include "farfield/gpu/gl_barrier_check_hooks.h"
#include "farfield/gpu/gl_counters.h"

namespace farfield::gpu {

namespace barrier_check {

std::atomic<bool> g_on{false};
std::atomic<bool> g_print{true};
// Totals over every thread, for the summary printed at exit (a thread's own state is gone by then).
std::atomic<uint64_t> g_hazard_calls{0}, g_distinct_hazards{0}, g_checked{0}, g_unknown{0};

namespace {

constexpr GLbitfield kAllBits = 0xFFFFFFFFu;

// A command that accessed a resource: its entry point and program, named only when a message needs them.
struct Command {
  const char* entry = "";
  GLuint program = 0;
};

// A buffer or a texture: the barrier bits it is still owed since a shader last wrote it (by which command, through
// which binding), and whether a shader or an indirect command read it since the last barrier that orders a later
// shader write after that read.
struct Resource {
  GLbitfield owed = 0;
  Command writer;
  const char* written_at = "";
  int written_index = -1;
  bool read = false;
  Command reader;
  // False from storage made without data until something writes it (a clear, an upload, a copy, a shader): a GPU's
  // allocator may hand out memory another buffer of the process left behind.
  bool defined = true;
};

struct Program {
  GlslBindings declared;  // by its shaders together
  std::vector<int> buffers, written_buffers, images, written_images, samplers;  // the same, for the checks' loops
};

// Binding points and units to the object bound there (0: none).
struct Points {
  std::vector<GLuint> bound;
  void set(GLuint at, GLuint object) {
    if (at >= bound.size()) bound.resize(at + 1, 0);
    bound[at] = object;
  }
  GLuint at(int i) const { return size_t(i) < bound.size() ? bound[size_t(i)] : 0; }
  void forget(GLuint object) {
    for (GLuint& b : bound)
      if (b == object) b = 0;
  }
};

struct State {
  std::unordered_map<GLuint, GlslBindings> shaders;
  std::unordered_map<GLuint, std::string> shader_names;
  std::unordered_map<GLuint, Program> programs;
  std::unordered_map<GLuint, std::string> program_names;  // kept after a program is deleted (messages name it)
  GLuint program = 0;
  Points storage, images, units;
  GLuint draw_indirect = 0, dispatch_indirect = 0, parameter = 0;
  std::unordered_map<GLuint, Resource> buffers, textures;
  std::unordered_map<GLuint, GLsizeiptr> buffer_bytes;  // storage sizes
  std::unordered_map<GLuint, GLuint> element_buffers;   // vertex array -> its element buffer
  GLuint vertex_array = 0;
  std::unordered_map<GLuint, std::unordered_map<GLenum, GLuint>> attachments;  // framebuffer -> attachment -> texture
  GLuint draw_framebuffer = 0;
  std::vector<GlBarrierHazard> hazards;
  std::unordered_map<std::string, size_t> hazard_index;
  GlBarrierCheckCounts counts;
};
// Each thread's state, made on its first followed call and kept until the process ends. A thread_local State itself
// (a dynamic initialiser and a destructor per thread) made LeakSanitizer's exit-time tracer crash in tests whose
// worker threads make GL calls; a plain pointer per thread and a registry do not.
std::mutex g_states_mutex;
std::vector<std::unique_ptr<State>>& states() {
  static std::vector<std::unique_ptr<State>> all;
  return all;
}
State& threadState() {
  thread_local State* mine = nullptr;
  if (!mine) {
    const std::lock_guard<std::mutex> lock(g_states_mutex);
    states().push_back(std::make_unique<State>());
    mine = states().back().get();
  }
  return *mine;
}

const char* bitName(GLbitfield bit) {
  switch (bit) {
    case GL_SHADER_STORAGE_BARRIER_BIT: return "GL_SHADER_STORAGE_BARRIER_BIT";
    case GL_COMMAND_BARRIER_BIT: return "GL_COMMAND_BARRIER_BIT";
    case GL_BUFFER_UPDATE_BARRIER_BIT: return "GL_BUFFER_UPDATE_BARRIER_BIT";
    case GL_TEXTURE_FETCH_BARRIER_BIT: return "GL_TEXTURE_FETCH_BARRIER_BIT";
    case GL_SHADER_IMAGE_ACCESS_BARRIER_BIT: return "GL_SHADER_IMAGE_ACCESS_BARRIER_BIT";
    case GL_TEXTURE_UPDATE_BARRIER_BIT: return "GL_TEXTURE_UPDATE_BARRIER_BIT";
    default: return "a barrier bit";
  }
}

std::string programName(GLuint program) {
  const auto it = threadState().program_names.find(program);
  return it != threadState().program_names.end() ? it->second : "program " + std::to_string(program);
}

// "glDispatchCompute (gpu_cull.comp.glsl)"; a buffer operation has no program.
std::string name(const Command& c) {
  return c.program ? std::string(c.entry) + " (" + programName(c.program) + ")" : std::string(c.entry);
}

// "shader storage binding 7", "its draw commands".
std::string place(const char* kind, int index) {
  return index >= 0 ? std::string(kind) + " " + std::to_string(index) : std::string(kind);
}

void record(std::string message) {
  State& s = threadState();
  const auto [it, fresh] = s.hazard_index.emplace(message, s.hazards.size());
  ++g_hazard_calls;
  if (fresh) {
    ++g_distinct_hazards;
    s.hazards.push_back({std::move(message), 0});
    if (g_print.load(std::memory_order_relaxed))
      std::fprintf(stderr, "FF_GL_BARRIER_HAZARD: %s\n", s.hazards.back().message.c_str());
  }
  ++s.hazards[it->second].count;
}

// An access of `r` that needs `bit`: a hazard when a shader wrote it and no barrier with that bit came since.
// Messages name a resource by how it was bound, not by its object number, so that one message stands for one place
// in the code whatever objects met there.
void needs(const Resource& r, GLbitfield bit, const Command& by, const char* verb, const char* kind, int index = -1) {
  if (!(r.owed & bit)) return;
  record(name(by) + " " + verb + " " + place(kind, index) + ", written at " + place(r.written_at, r.written_index) +
         " by " + name(r.writer) + ", with no glMemoryBarrier(" + bitName(bit) + ") since");
}

// A shader's write to `r` after an earlier command's read that no barrier with `bit` ordered it after.
void writeAfterRead(const Resource& r, GLbitfield bit, const Command& by, const char* kind, int index) {
  if (!r.read || (r.owed & bit)) return;  // (a write after a write is the hazard `needs` reports)
  record(name(by) + " writes " + place(kind, index) + ", read before by " + name(r.reader) +
         ", with no glMemoryBarrier(" + bitName(bit) + ") since (a write after a read)");
}

// A read of a buffer whose storage was made without data and that nothing wrote since.
void undefinedRead(const Resource& r, const Command& by, const char* kind, int index = -1) {
  if (!r.defined)
    record(name(by) + " reads " + place(kind, index) + ", a buffer made without data that nothing wrote since");
}

bool has(const std::vector<int>& v, int x) { return std::find(v.begin(), v.end(), x) != v.end(); }

// The shader accesses of a dispatch or draw by program `p`: first every check, then what the command leaves (reads
// that later writes must be ordered after, writes that later reads need a barrier for).
void shaderAccesses(const Command& by, const Program& p) {
  State& s = threadState();
  for (int i : p.buffers)
    if (const GLuint b = s.storage.at(i)) {
      const Resource& r = s.buffers[b];
      needs(r, GL_SHADER_STORAGE_BARRIER_BIT, by, "reads", "shader storage binding", i);
      // (a block the program may write may only be written: only a readonly one is surely read)
      if (!has(p.written_buffers, i)) undefinedRead(r, by, "shader storage binding", i);
      if (has(p.written_buffers, i)) writeAfterRead(r, GL_SHADER_STORAGE_BARRIER_BIT, by, "shader storage binding", i);
    }
  for (int u : p.samplers)
    if (const GLuint t = s.units.at(u))
      needs(s.textures[t], GL_TEXTURE_FETCH_BARRIER_BIT, by, "reads", "texture unit", u);
  for (int u : p.images)
    if (const GLuint t = s.images.at(u)) {
      const Resource& r = s.textures[t];
      needs(r, GL_SHADER_IMAGE_ACCESS_BARRIER_BIT, by, "reads", "image unit", u);
      if (has(p.written_images, u)) writeAfterRead(r, GL_SHADER_IMAGE_ACCESS_BARRIER_BIT, by, "image unit", u);
    }
  const auto leave = [&](Resource& r, bool written, const char* kind, int index) {
    r.read = true;
    r.reader = by;
    if (!written) return;
    r.defined = true;
    r.owed = kAllBits;
    r.writer = by;
    r.written_at = kind;
    r.written_index = index;
  };
  for (int i : p.buffers)
    if (const GLuint b = s.storage.at(i)) leave(s.buffers[b], has(p.written_buffers, i), "shader storage binding", i);
  for (int u : p.samplers)
    if (const GLuint t = s.units.at(u)) leave(s.textures[t], false, "texture unit", u);
  for (int u : p.images)
    if (const GLuint t = s.images.at(u)) leave(s.textures[t], has(p.written_images, u), "image unit", u);
}

// A draw that samples a texture attached to the framebuffer it draws into: a feedback loop, whose texels and
// fragments are undefined (OpenGL 4.6, 8.14.2.1 and 9.3.1) even where llvmpipe's tiles happen to give the old ones.
void feedbackLoops(const Command& by, const Program& p) {
  State& s = threadState();
  const auto fb = s.attachments.find(s.draw_framebuffer);
  if (s.draw_framebuffer == 0 || fb == s.attachments.end()) return;
  for (int u : p.samplers)
    if (const GLuint t = s.units.at(u))
      for (const auto& [attachment, texture] : fb->second)
        if (texture == t)
          record(name(by) + " samples texture unit " + std::to_string(u) +
                 ", a texture attached to the framebuffer it draws into (a feedback loop)");
}

// The current program, or null (counted) when the check does not know it.
const Program* current() {
  State& s = threadState();
  const auto it = s.programs.find(s.program);
  if (it == s.programs.end()) {
    ++s.counts.unknown_program;
    ++g_unknown;
    return nullptr;
  }
  ++s.counts.checked;
  ++g_checked;
  return &it->second;
}

// A command's indirect buffer (its commands, dispatch size or draw count): checked before the command's shader
// accesses, marked read after them (the command's own writes come after its indirect read).
void indirectNeeds(GLuint buffer, const Command& by, const char* what) {
  if (buffer == 0) return;
  const Resource& r = threadState().buffers[buffer];
  needs(r, GL_COMMAND_BARRIER_BIT, by, "reads", what);
  undefinedRead(r, by, what);
}
void indirectRead(GLuint buffer, const Command& by) {
  if (buffer == 0) return;
  Resource& r = threadState().buffers[buffer];
  r.read = true;
  r.reader = by;
}

std::vector<int> list(const std::set<int>& s) { return {s.begin(), s.end()}; }

}  // namespace

void shaderSource(GLuint shader, GLsizei count, const GLchar* const* strings, const GLint* lengths) {
  std::string text;
  for (GLsizei i = 0; i < count; ++i) {
    if (!strings[i]) continue;
    if (lengths && lengths[i] >= 0) text.append(strings[i], size_t(lengths[i]));
    else text.append(strings[i]);
  }
  threadState().shaders[shader] = glslBindings(text);
}

void attachShader(GLuint program, GLuint shader) {
  State& s = threadState();
  if (!s.programs.count(program)) s.program_names[program].clear();  // a new program (its name may be reused)
  Program& p = s.programs[program];
  if (const auto it = s.shaders.find(shader); it != s.shaders.end()) p.declared |= it->second;
  const GlslBindings& d = p.declared;
  p.buffers = list(d.buffers), p.written_buffers = list(d.written_buffers), p.images = list(d.images);
  p.written_images = list(d.written_images), p.samplers = list(d.samplers);
  const auto named = s.shader_names.find(shader);
  const std::string shader_name = named != s.shader_names.end() ? named->second : "shader " + std::to_string(shader);
  std::string& program_name = s.program_names[program];
  program_name += (program_name.empty() ? "" : " + ") + shader_name;
}

void deleteProgram(GLuint program) { threadState().programs.erase(program); }
void useProgram(GLuint program) { threadState().program = program; }

void bindBufferBase(GLenum target, GLuint index, GLuint buffer) {
  if (target == GL_SHADER_STORAGE_BUFFER) threadState().storage.set(index, buffer);
}

void bindBuffer(GLenum target, GLuint buffer) {
  State& s = threadState();
  if (target == GL_DRAW_INDIRECT_BUFFER) s.draw_indirect = buffer;
  else if (target == GL_DISPATCH_INDIRECT_BUFFER) s.dispatch_indirect = buffer;
  else if (target == GL_PARAMETER_BUFFER_ARB) s.parameter = buffer;
}

void bindTextureUnit(GLuint unit, GLuint texture) { threadState().units.set(unit, texture); }
void bindImageTexture(GLuint unit, GLuint texture) { threadState().images.set(unit, texture); }

void deleteBuffers(GLsizei n, const GLuint* buffers) {
  State& s = threadState();
  for (GLsizei i = 0; i < n; ++i) {
    const GLuint b = buffers[i];
    s.buffers.erase(b);
    s.buffer_bytes.erase(b);
    s.storage.forget(b);
    for (GLuint* bound : {&s.draw_indirect, &s.dispatch_indirect, &s.parameter})
      if (*bound == b) *bound = 0;
  }
}

void deleteTextures(GLsizei n, const GLuint* textures) {
  State& s = threadState();
  for (GLsizei i = 0; i < n; ++i) {
    s.textures.erase(textures[i]);
    for (auto& [fb, attached] : s.attachments)
      for (auto& [attachment, texture] : attached)
        if (texture == textures[i]) texture = 0;
    s.units.forget(textures[i]);
    s.images.forget(textures[i]);
  }
}

void memoryBarrier(GLbitfield bits) {
  State& s = threadState();
  for (auto& [id, r] : s.buffers) {
    r.owed &= ~bits;
    if (bits & GL_SHADER_STORAGE_BARRIER_BIT) r.read = false;
  }
  for (auto& [id, r] : s.textures) {
    r.owed &= ~bits;
    if (bits & GL_SHADER_IMAGE_ACCESS_BARRIER_BIT) r.read = false;
  }
}

void dispatch(const char* entry, bool indirect_size) {
  const Program* p = current();
  if (!p) return;
  const Command by{entry, threadState().program};
  if (indirect_size) indirectNeeds(threadState().dispatch_indirect, by, "its dispatch size");
  shaderAccesses(by, *p);
  if (indirect_size) indirectRead(threadState().dispatch_indirect, by);
}

void draw(const char* entry, bool indirect_commands, bool count) {
  const Program* p = current();
  if (!p) return;
  const Command by{entry, threadState().program};
  feedbackLoops(by, *p);
  if (indirect_commands) indirectNeeds(threadState().draw_indirect, by, "its draw commands");
  if (count) indirectNeeds(threadState().parameter, by, "its draw count");
  shaderAccesses(by, *p);
  if (indirect_commands) indirectRead(threadState().draw_indirect, by);
  if (count) indirectRead(threadState().parameter, by);
}

void bufferUpdate(const char* entry, GLuint buffer, bool reads) {
  const auto it = threadState().buffers.find(buffer);
  if (it == threadState().buffers.end()) return;
  needs(it->second, GL_BUFFER_UPDATE_BARRIER_BIT, {entry, 0}, reads ? "reads" : "overwrites", "a buffer");
  if (reads) undefinedRead(it->second, {entry, 0}, "a buffer");
  else it->second.defined = true;  // (a partial write counts: the check does not follow ranges)
}

void bufferStorage(GLuint buffer, GLsizeiptr bytes, bool with_data) {
  Resource fresh;
  fresh.defined = with_data;
  threadState().buffers[buffer] = fresh;
  threadState().buffer_bytes[buffer] = bytes;
}

void framebufferTexture(GLuint framebuffer, GLenum attachment, GLuint texture) {
  threadState().attachments[framebuffer][attachment] = texture;
}
void bindFramebuffer(GLenum target, GLuint framebuffer) {
  if (target == GL_FRAMEBUFFER || target == GL_DRAW_FRAMEBUFFER) threadState().draw_framebuffer = framebuffer;
}
void deleteFramebuffers(GLsizei n, const GLuint* framebuffers) {
  for (GLsizei i = 0; i < n; ++i) {
    threadState().attachments.erase(framebuffers[i]);
    if (threadState().draw_framebuffer == framebuffers[i]) threadState().draw_framebuffer = 0;
  }
}

void vertexArrayElementBuffer(GLuint vertex_array, GLuint buffer) { threadState().element_buffers[vertex_array] = buffer; }
void bindVertexArray(GLuint vertex_array) { threadState().vertex_array = vertex_array; }

namespace {

// The driver's own entry points, not the counted wrappers: the check's readbacks are not the frame's calls.
PFNGLGETNAMEDBUFFERSUBDATAPROC g_read = nullptr;

template <class T>
std::vector<T> readBack(GLuint buffer, GLintptr offset, size_t count) {
  std::vector<T> out(count);
  if (!g_read) g_read = reinterpret_cast<PFNGLGETNAMEDBUFFERSUBDATAPROC>(eglGetProcAddress("glGetNamedBufferSubData"));
  if (g_read && count) g_read(buffer, offset, GLsizeiptr(count * sizeof(T)), out.data());
  return out;
}

}  // namespace

void indexedIndirect(const char* entry, GLenum type, const void* indirect, GLsizei drawcount, GLsizei stride,
                     GLintptr count_offset) {
  State& s = threadState();
  const auto element = s.element_buffers.find(s.vertex_array);
  if (s.draw_indirect == 0 || element == s.element_buffers.end() || element->second == 0) return;
  const auto bytes = s.buffer_bytes.find(element->second);
  const auto commands_bytes = s.buffer_bytes.find(s.draw_indirect);
  if (bytes == s.buffer_bytes.end() || commands_bytes == s.buffer_bytes.end()) return;  // made before the check
  const GLsizeiptr index_size = type == GL_UNSIGNED_SHORT ? 2 : type == GL_UNSIGNED_BYTE ? 1 : 4;
  const uint64_t indices = uint64_t(bytes->second / index_size);
  const GLintptr first = GLintptr(reinterpret_cast<uintptr_t>(indirect));
  const GLsizei step = stride ? stride : GLsizei(5 * sizeof(uint32_t));
  GLsizei n = drawcount;  // (the maximum, for a draw with a count)
  if (count_offset >= 0 && s.parameter != 0)
    n = std::min<GLsizei>(n, GLsizei(readBack<uint32_t>(s.parameter, count_offset, 1)[0]));
  if (n <= 0) return;
  if (first + GLintptr(n - 1) * step + GLintptr(5 * sizeof(uint32_t)) > commands_bytes->second) {
    record(std::string(entry) + " (" + programName(s.program) + ") reads " + std::to_string(n) +
           " draw commands past the end of its indirect buffer");
    return;
  }
  const std::vector<uint32_t> words =
      readBack<uint32_t>(s.draw_indirect, first, size_t(n - 1) * size_t(step / 4) + 5);
  s.counts.indirect_commands += uint64_t(n);
  for (GLsizei k = 0; k < n; ++k) {
    const uint32_t* c = &words[size_t(k) * size_t(step / 4)];  // count, instances, first index, base vertex, base inst.
    if (c[0] == 0 || c[1] == 0) continue;
    if (uint64_t(c[2]) + c[0] > indices) {
      record(std::string(entry) + " (" + programName(s.program) + ") draws a command whose indices [" +
             std::to_string(c[2]) + ", " + std::to_string(uint64_t(c[2]) + c[0]) + ") pass the " +
             std::to_string(indices) + " of its element buffer (a GPU may fault where llvmpipe reads zeros)");
      return;
    }
  }
}

void mapBuffer(GLuint buffer, GLbitfield access) {
  if (access & GL_MAP_WRITE_BIT)
    if (const auto it = threadState().buffers.find(buffer); it != threadState().buffers.end()) it->second.defined = true;
}

void textureUpdate(const char* entry, GLuint texture, bool reads) {
  const auto it = threadState().textures.find(texture);
  if (it != threadState().textures.end())
    needs(it->second, GL_TEXTURE_UPDATE_BARRIER_BIT, {entry, 0}, reads ? "reads" : "overwrites", "a texture");
}

}  // namespace barrier_check

bool setGlBarrierCheck(bool on) {
  if (on && !glCountersInstalled()) return false;
  barrier_check::g_on = on;
  return true;
}

bool glBarrierCheckOn() { return barrier_check::on(); }

void setGlBarrierHazardsPrinted(bool on) { barrier_check::g_print = on; }

std::vector<GlBarrierHazard> glBarrierHazards() { return barrier_check::threadState().hazards; }

void clearGlBarrierHazards() {
  barrier_check::threadState().hazards.clear();
  barrier_check::threadState().hazard_index.clear();
  barrier_check::threadState().counts = {};
}

GlBarrierCheckCounts glBarrierCheckCounts() { return barrier_check::threadState().counts; }

void nameGlShader(uint32_t shader, const std::string& name) {
  if (barrier_check::on()) barrier_check::threadState().shader_names[shader] = name;
}

void enableGlBarrierCheckFromEnvironment(bool window_context) {
  const char* env = std::getenv("FF_GL_BARRIER_CHECK");
  if (!env || !*env || std::strcmp(env, "0") == 0) return;
  if (!installGlCounters(window_context) || !setGlBarrierCheck(true)) {
    static bool warned = false;
    if (!warned) std::fprintf(stderr, "FF_GL_BARRIER_CHECK: the GL counters could not be installed; no check\n");
    warned = true;
    return;
  }
  // One line at exit, so that a quiet run is known to have been checked.
  static std::once_flag summary;
  std::call_once(summary, [] {
    std::atexit([] {
      using barrier_check::g_checked, barrier_check::g_distinct_hazards, barrier_check::g_hazard_calls;
      std::fprintf(stderr, "gl barrier check: %llu hazards (%llu calls) in %llu dispatches and draws checked",
                   static_cast<unsigned long long>(g_distinct_hazards.load()),
                   static_cast<unsigned long long>(g_hazard_calls.load()),
                   static_cast<unsigned long long>(g_checked.load()));
      if (const uint64_t unknown = barrier_check::g_unknown.load())
        std::fprintf(stderr, ", %llu of programs made before the check", static_cast<unsigned long long>(unknown));
      std::fprintf(stderr, "\n");
    });
  });
}

}  // namespace farfield::gpu
