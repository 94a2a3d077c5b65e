// A check of the memory barriers Farfield's GL calls need, made on any driver (llvmpipe included).
//
// Why: a shader's writes to storage buffers and images are incoherent. OpenGL makes them visible to a later command
// only through glMemoryBarrier with the bit of that command's kind of read (OpenGL 4.6, section 7.13.2): a storage
// buffer read by a later shader (GL_SHADER_STORAGE_BARRIER_BIT), indirect commands and counts
// (GL_COMMAND_BARRIER_BIT), buffer copies, clears and reads (GL_BUFFER_UPDATE_BARRIER_BIT), texture fetches
// (GL_TEXTURE_FETCH_BARRIER_BIT), image loads (GL_SHADER_IMAGE_ACCESS_BARRIER_BIT), texture reads and updates
// (GL_TEXTURE_UPDATE_BARRIER_BIT). A shader's write to a buffer or image that an earlier command read also waits for
// that read only across a barrier with GL_SHADER_STORAGE_BARRIER_BIT or GL_SHADER_IMAGE_ACCESS_BARRIER_BIT (a write
// after a read). llvmpipe finishes all work at every glMemoryBarrier whatever its bits and runs compute on the
// calling thread, so a missing bit never shows there; on a GPU it is a frame that reads stale commands or counts.
//
// How: with the check on, the GL counters' wrappers (gl_counters.h) follow the calls that matter: the shader sources
// (each shader's storage-buffer, image and sampler bindings, and which of them it may write: those not declared
// readonly), the programs, the buffers and textures bound to indexed points and units, the indirect buffers, every
// dispatch and draw, every barrier, and the buffer and texture operations that read or overwrite a resource. Each
// resource remembers the barrier bits it is still owed since a shader last wrote it, and whether a shader or an
// indirect command read it since the last barrier that orders a later write. A call that needs a bit still owed is
// a hazard, recorded with the entry point, the program (by its shaders' names) and the resource. So is a read of a
// buffer whose storage was made without data before anything wrote it (a readonly storage block, an indirect buffer,
// a copy's source): llvmpipe's fresh memory is usually zero, a GPU driver's may hold another buffer's old contents.
// And an indexed indirect draw's commands are read back (by the driver's own entry point, outside the counted calls:
// a wait that only the check makes) and each command's indices checked against the bound vertex array's element
// buffer: llvmpipe fetches zeros past its end, where a GPU may fault. And a draw that samples a texture attached to
// the framebuffer it draws into is a feedback loop (undefined texels and fragments on a GPU).
//
// Limits: whole buffers and textures (not ranges or levels); shaders' bindings as declared with layout(binding = N)
// (a sampler unit set by glUniform1i is not followed); vertex and index buffers written by shaders are not followed
// (Farfield's are not); programs compiled before the check was turned on are unknown to it and not checked.
//
// FF_GL_BARRIER_CHECK=1 in the environment turns it on for every context Farfield makes (gpu/context.h; a viewer's
// GLFW window too), prints each new hazard to stderr as "FF_GL_BARRIER_HAZARD: ...", which fails a test under ctest
// (tests/CMakeLists.txt; `make test` sets the variable for every test), and at exit one line: "gl barrier check: N
// hazards ...".
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "farfield/gpu/glsl_bindings.h"

namespace farfield::gpu {

// Turns the check on or off for the GL calls of every thread (each thread's context is followed apart); needs
// installGlCounters() (returns false without it). Programs compiled while it is off are not checked.
bool setGlBarrierCheck(bool on);
bool glBarrierCheckOn();
// Prints each new hazard to stderr ("FF_GL_BARRIER_HAZARD: ...") as it is found; on by default.
void setGlBarrierHazardsPrinted(bool on);

struct GlBarrierHazard {
  std::string message;
  uint64_t count = 0;  // how many calls made it
};
// The calling thread's hazards since the last clear, in the order first found.
std::vector<GlBarrierHazard> glBarrierHazards();
void clearGlBarrierHazards();
// What the check followed on the calling thread since the last clear: dispatches and draws it checked, those of
// programs it did not know (compiled before the check was on), and indirect commands it checked.
struct GlBarrierCheckCounts {
  uint64_t checked = 0, unknown_program = 0;
  uint64_t indirect_commands = 0;  // indexed indirect draw commands read back and checked against their indices
};
GlBarrierCheckCounts glBarrierCheckCounts();

// Names a shader object for the hazards' messages (gpu/program.cpp: the embedded shader's name).
void nameGlShader(uint32_t shader, const std::string& name);

// FF_GL_BARRIER_CHECK set (and not "0"): installs the GL counters and turns the check on.
// Called by every context Farfield makes current for the first time (`window_context`: a GLFW window's).
void enableGlBarrierCheckFromEnvironment(bool window_context = false);

}  // namespace farfield::gpu
