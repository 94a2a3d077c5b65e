// The calls the GL counters' wrappers make into the barrier check (gl_barrier_check.h) before each followed entry
// point, with its arguments. Internal to the gpu module.
#pragma once

#include <epoxy/gl.h>

#include <atomic>

namespace farfield::gpu::barrier_check {

extern std::atomic<bool> g_on;
inline bool on() { return g_on.load(std::memory_order_relaxed); }

void shaderSource(GLuint shader, GLsizei count, const GLchar* const* strings, const GLint* lengths);
void attachShader(GLuint program, GLuint shader);
void deleteProgram(GLuint program);
void useProgram(GLuint program);
void bindBufferBase(GLenum target, GLuint index, GLuint buffer);
void bindBuffer(GLenum target, GLuint buffer);
void bindTextureUnit(GLuint unit, GLuint texture);
void bindImageTexture(GLuint unit, GLuint texture);
void deleteBuffers(GLsizei n, const GLuint* buffers);
void deleteTextures(GLsizei n, const GLuint* textures);
void memoryBarrier(GLbitfield bits);

// A dispatch or a draw by the current program; `indirect`: its commands come from the bound dispatch or draw
// indirect buffer, `count`: its draw count from the bound parameter buffer.
void dispatch(const char* entry, bool indirect);
void draw(const char* entry, bool indirect, bool count);

// Buffer and texture operations that read or overwrite what a shader may have written.
void bufferUpdate(const char* entry, GLuint buffer, bool reads);
void textureUpdate(const char* entry, GLuint texture, bool reads);
// A buffer's storage, made with or without data; a map for writing (its contents then count as written).
void bufferStorage(GLuint buffer, GLsizeiptr bytes, bool with_data);
void mapBuffer(GLuint buffer, GLbitfield access);
// Indexed indirect draws: every command read back (outside the counted calls) and its indices checked against the
// bound vertex array's element buffer. `count_offset` >= 0: the draw count is read from the parameter buffer there.
void vertexArrayElementBuffer(GLuint vertex_array, GLuint buffer);
// Framebuffer attachments and the draw framebuffer: a draw that samples a texture attached to it is a feedback loop.
void framebufferTexture(GLuint framebuffer, GLenum attachment, GLuint texture);
void bindFramebuffer(GLenum target, GLuint framebuffer);
void deleteFramebuffers(GLsizei n, const GLuint* framebuffers);
void bindVertexArray(GLuint vertex_array);
void indexedIndirect(const char* entry, GLenum type, const void* indirect, GLsizei drawcount, GLsizei stride,
                     GLintptr count_offset);

}  // namespace farfield::gpu::barrier_check
