// The barrier check (gpu/gl_barrier_check.h): the hazards it finds in small compute programs with each barrier left
// out, and does not find with it. The GPU culler's and the crowd's passes have tests of their own, and every test's
// GL calls are checked under `make test` (the Makefile sets FF_GL_BARRIER_CHECK=1, tests/CMakeLists.txt fails a test
// that prints a hazard).
#include "farfield/gpu/gl_barrier_check.h"

#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "farfield/gpu/gl_counters.h"
#include "farfield/gpu/render_target.h"
#include "gpu/barrier_check_helpers.h"
#include "gpu/gpu_fixture.h"

namespace farfield::gpu {
namespace {

// A program drawing a point at the origin with fragment shader `fragment`, compiled with the check on.
GLuint pointProgram(const char* fragment, const std::string& name) {
  const char* vertex = "#version 450 core\nvoid main() { gl_Position = vec4(0.0, 0.0, 0.0, 1.0); }\n";
  GLuint shaders[2] = {glCreateShader(GL_VERTEX_SHADER), glCreateShader(GL_FRAGMENT_SHADER)};
  nameGlShader(shaders[0], "point.vert");
  nameGlShader(shaders[1], name);
  glShaderSource(shaders[0], 1, &vertex, nullptr);
  glShaderSource(shaders[1], 1, &fragment, nullptr);
  const GLuint program = glCreateProgram();
  for (GLuint sh : shaders) {
    glCompileShader(sh);
    glAttachShader(program, sh);
  }
  glLinkProgram(program);
  for (GLuint sh : shaders) glDeleteShader(sh);
  GLint ok = 0;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  EXPECT_EQ(ok, GL_TRUE) << name;
  return program;
}

class GlBarrierCheckTest : public test::GpuTest {
 protected:
  void SetUp() override {
    GpuTest::SetUp();
    if (!installGlCounters() || !setGlBarrierCheck(true))
      GTEST_SKIP() << "GL counters unavailable (FF_GL_COUNTERS=0 or no EGL context)";
    setGlBarrierHazardsPrinted(false);  // these hazards are made on purpose (ctest fails on printed ones)
    glMemoryBarrier(GL_ALL_BARRIER_BITS);  // nothing owed from earlier tests
    clearGlBarrierHazards();
    writer_ = test::computeProgram(R"(#version 450 core
layout(local_size_x = 1) in;
layout(std430, binding = 0) buffer Out { uvec4 args; uint v[]; };
void main() { args = uvec4(1u, 1u, 1u, 7u); v[0] = 5u; })",
                             "writer.comp");
    reader_ = test::computeProgram(R"(#version 450 core
layout(local_size_x = 1) in;
layout(std430, binding = 1) readonly buffer In { uvec4 args; uint v[]; };
layout(std430, binding = 2) buffer Sum { uint total; };
void main() { total += v[0]; })",
                             "reader.comp");
    imager_ = test::computeProgram(R"(#version 450 core
layout(local_size_x = 1) in;
layout(r32f, binding = 0) writeonly uniform image2D u_out;
void main() { imageStore(u_out, ivec2(0), vec4(0.5)); })",
                             "imager.comp");
    sampler_ = test::computeProgram(R"(#version 450 core
layout(local_size_x = 1) in;
layout(binding = 3) uniform sampler2D u_in;
layout(std430, binding = 2) buffer Sum { float total; };
void main() { total += texelFetch(u_in, ivec2(0), 0).r; })",
                              "sampler.comp");
    glCreateBuffers(3, buffers_);
    const std::vector<uint32_t> zeros(16, 0u);
    for (GLuint b : buffers_) glNamedBufferStorage(b, 64, zeros.data(), GL_DYNAMIC_STORAGE_BIT);
    glCreateTextures(GL_TEXTURE_2D, 1, &texture_);
    glTextureStorage2D(texture_, 1, GL_R32F, 1, 1);
  }
  void TearDown() override {
    if (writer_) {
      glDeleteProgram(writer_);
      glDeleteProgram(reader_);
      glDeleteProgram(imager_);
      glDeleteProgram(sampler_);
      glDeleteBuffers(3, buffers_);
      glDeleteTextures(1, &texture_);
      glMemoryBarrier(GL_ALL_BARRIER_BITS);
    }
    clearGlBarrierHazards();
    setGlBarrierHazardsPrinted(true);
    setGlBarrierCheck(false);
    enableGlBarrierCheckFromEnvironment();  // back as ctest runs every test
  }
  // The writer program writes buffers_[0].
  void write() {
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, buffers_[0]);
    glUseProgram(writer_);
    glDispatchCompute(1, 1, 1);
  }
  // The reader program reads `buffer` and writes buffers_[2].
  void read(GLuint buffer) {
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, buffer);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, buffers_[2]);
    glUseProgram(reader_);
    glDispatchCompute(1, 1, 1);
    glMemoryBarrier(GL_ALL_BARRIER_BITS);  // its own write of buffers_[2] settled
  }
  // The hazards since the last call, as one string (empty: none), and a fresh start.
  std::string hazards() { return test::takeHazards(); }

  GLuint writer_ = 0, reader_ = 0, imager_ = 0, sampler_ = 0;
  GLuint buffers_[3] = {};
  GLuint texture_ = 0;
};

TEST_F(GlBarrierCheckTest, ACopyOfAShadersWritesNeedsTheBufferUpdateBit) {
  write();
  glCopyNamedBufferSubData(buffers_[0], buffers_[1], 0, 0, 16);
  const std::string h = hazards();
  EXPECT_NE(h.find("glCopyNamedBufferSubData reads a buffer, written at shader storage binding 0 by "
                   "glDispatchCompute (writer.comp), with no glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT)"),
            std::string::npos)
      << h;
  write();
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);  // not the bit a copy needs
  glClearNamedBufferData(buffers_[0], GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
  EXPECT_NE(hazards().find("glClearNamedBufferData overwrites a buffer"), std::string::npos);
  write();
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  glCopyNamedBufferSubData(buffers_[0], buffers_[1], 0, 0, 16);
  uint32_t got[4] = {};
  glGetNamedBufferSubData(buffers_[1], 0, 16, got);
  EXPECT_EQ(glBarrierCheckCounts().checked, 1u);  // the one dispatch since the last clear
  EXPECT_EQ(hazards(), "");
  EXPECT_EQ(got[3], 7u);  // what the writer wrote, copied
}

TEST_F(GlBarrierCheckTest, AnIndirectDispatchFromAShadersWritesNeedsTheCommandBit) {
  for (const GLbitfield bits : {GLbitfield(0), GLbitfield(GL_SHADER_STORAGE_BARRIER_BIT),
                                GLbitfield(GL_COMMAND_BARRIER_BIT)}) {
    write();
    if (bits) glMemoryBarrier(bits);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, buffers_[1]);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, buffers_[2]);
    glUseProgram(reader_);
    glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, buffers_[0]);
    glDispatchComputeIndirect(0);
    glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, 0);
    glMemoryBarrier(GL_ALL_BARRIER_BITS);
    const std::string h = hazards();
    if (bits == GL_COMMAND_BARRIER_BIT)
      EXPECT_EQ(h, "");
    else
      EXPECT_NE(h.find("glDispatchComputeIndirect (reader.comp) reads its dispatch size, written at shader storage "
                       "binding 0 by glDispatchCompute (writer.comp), with no glMemoryBarrier(GL_COMMAND_BARRIER_BIT)"),
                std::string::npos)
          << "barrier bits " << bits << ": " << h;
  }
}

TEST_F(GlBarrierCheckTest, AShadersReadOfAnotherShadersWritesNeedsTheStorageBit) {
  write();
  glMemoryBarrier(GL_COMMAND_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);  // not the bit a shader's read needs
  read(buffers_[0]);
  EXPECT_NE(hazards().find("glDispatchCompute (reader.comp) reads shader storage binding 1, written at shader storage "
                           "binding 0 by glDispatchCompute (writer.comp), with no "
                           "glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT)"),
            std::string::npos);
  write();
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
  read(buffers_[0]);
  EXPECT_EQ(hazards(), "");
}

TEST_F(GlBarrierCheckTest, AShadersWriteAfterAnEarlierReadNeedsTheStorageBit) {
  read(buffers_[0]);  // ends with a barrier: the read is ordered
  write();
  EXPECT_EQ(hazards(), "");
  glMemoryBarrier(GL_ALL_BARRIER_BITS);
  // The same without the barrier after the read: the writer's write may overtake it.
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, buffers_[0]);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, buffers_[2]);
  glUseProgram(reader_);
  glDispatchCompute(1, 1, 1);
  write();
  EXPECT_NE(hazards().find("glDispatchCompute (writer.comp) writes shader storage binding 0, read before by "
                           "glDispatchCompute (reader.comp), with no glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT) "
                           "since (a write after a read)"),
            std::string::npos);
  // A buffer only ever read (declared readonly) owes nothing.
  glMemoryBarrier(GL_ALL_BARRIER_BITS);
  read(buffers_[1]);
  glClearNamedBufferData(buffers_[1], GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
  EXPECT_EQ(hazards(), "");
}

TEST_F(GlBarrierCheckTest, ImageStoresNeedTheFetchAndUpdateBitsBeforeTheyAreRead) {
  glBindImageTexture(0, texture_, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
  glUseProgram(imager_);
  glDispatchCompute(1, 1, 1);
  glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);  // not the bit a texture fetch needs
  glBindTextureUnit(3, texture_);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, buffers_[2]);
  glUseProgram(sampler_);
  glDispatchCompute(1, 1, 1);
  float texel = 0.0f;
  glGetTextureImage(texture_, 0, GL_RED, GL_FLOAT, sizeof(texel), &texel);
  const std::string h = hazards();
  EXPECT_NE(h.find("glDispatchCompute (sampler.comp) reads texture unit 3, written at image unit 0 by "
                   "glDispatchCompute (imager.comp), with no glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT)"),
            std::string::npos)
      << h;
  EXPECT_NE(h.find("glGetTextureImage reads a texture, written at image unit 0"), std::string::npos) << h;
  // A new image store after that fetch: a write after a read, unless GL_SHADER_IMAGE_ACCESS_BARRIER_BIT came between.
  glUseProgram(imager_);
  glDispatchCompute(1, 1, 1);
  EXPECT_NE(hazards().find("writes image unit 0, read before by glDispatchCompute (sampler.comp)"), std::string::npos);
  glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
  glUseProgram(sampler_);
  glDispatchCompute(1, 1, 1);
  glGetTextureImage(texture_, 0, GL_RED, GL_FLOAT, sizeof(texel), &texel);
  EXPECT_EQ(hazards(), "");
  EXPECT_FLOAT_EQ(texel, 0.5f);
  glBindTextureUnit(3, 0);
  glUseProgram(0);
}

TEST_F(GlBarrierCheckTest, AReadOfABufferMadeWithoutDataBeforeAnythingWroteItIsFound) {
  GLuint fresh[2] = {};
  glCreateBuffers(2, fresh);
  for (GLuint b : fresh) glNamedBufferStorage(b, 64, nullptr, GL_DYNAMIC_STORAGE_BIT);
  read(fresh[0]);
  uint32_t got = 0;
  glGetNamedBufferSubData(fresh[1], 0, 4, &got);
  const std::string h = hazards();
  EXPECT_NE(h.find("glDispatchCompute (reader.comp) reads shader storage binding 1, a buffer made without data that "
                   "nothing wrote since"),
            std::string::npos)
      << h;
  EXPECT_NE(h.find("glGetNamedBufferSubData reads a buffer, a buffer made without data"), std::string::npos) << h;
  // Written by a clear, a copy or a shader, it is defined.
  glClearNamedBufferData(fresh[0], GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
  glCopyNamedBufferSubData(buffers_[1], fresh[1], 0, 0, 64);
  read(fresh[0]);
  glGetNamedBufferSubData(fresh[1], 0, 4, &got);
  EXPECT_EQ(hazards(), "");
  glDeleteBuffers(2, fresh);
}

// Indexed indirect draws: a command whose indices pass the end of the element buffer is found (llvmpipe fetches
// zeros there; a GPU may fault), and the same command within it is not.
TEST_F(GlBarrierCheckTest, AnIndirectCommandPastItsElementBufferIsFound) {
  const GLuint program =
      pointProgram("#version 450 core\nout vec4 c;\nvoid main() { c = vec4(1.0); }\n", "white.frag");
  const std::vector<uint32_t> indices{0, 1, 2, 0, 2, 3};  // 6 indices
  GLuint elements = 0, commands = 0, vao = 0;
  glCreateBuffers(1, &elements);
  glNamedBufferStorage(elements, GLsizeiptr(indices.size() * 4), indices.data(), 0);
  glCreateVertexArrays(1, &vao);
  glVertexArrayElementBuffer(vao, elements);
  // (count, instances, first index, base vertex, base instance): within, then 3 indices from index 5.
  const std::vector<uint32_t> words{6, 1, 0, 0, 0, 3, 1, 5, 0, 0};
  glCreateBuffers(1, &commands);
  glNamedBufferStorage(commands, GLsizeiptr(words.size() * 4), words.data(), 0);
  RenderTarget target(4, 4);
  target.bind();
  glUseProgram(program);
  glBindVertexArray(vao);
  glBindBuffer(GL_DRAW_INDIRECT_BUFFER, commands);
  glEnable(GL_RASTERIZER_DISCARD);
  glMultiDrawElementsIndirect(GL_TRIANGLES, GL_UNSIGNED_INT, nullptr, 1, 0);
  EXPECT_EQ(hazards(), "");
  glMultiDrawElementsIndirect(GL_TRIANGLES, GL_UNSIGNED_INT, reinterpret_cast<const void*>(uintptr_t(20)), 1, 0);
  const std::string h = hazards();
  EXPECT_NE(h.find("glMultiDrawElementsIndirect (point.vert + white.frag)"), std::string::npos) << h;
  EXPECT_NE(h.find("draws a command whose indices [5, 8) pass the 6 of its element buffer"), std::string::npos) << h;
  glMultiDrawElementsIndirect(GL_TRIANGLES, GL_UNSIGNED_INT, nullptr, 3, 0);  // a third command past the buffer
  EXPECT_NE(hazards().find("reads 3 draw commands past the end of its indirect buffer"), std::string::npos);
  EXPECT_EQ(glGetError(), GLenum(GL_INVALID_OPERATION));  // (GL refuses that draw; the first two were drawn)
  EXPECT_EQ(glGetError(), GLenum(GL_NO_ERROR));
  glDisable(GL_RASTERIZER_DISCARD);
  glBindBuffer(GL_DRAW_INDIRECT_BUFFER, 0);
  glBindVertexArray(0);
  glUseProgram(0);
  glDeleteVertexArrays(1, &vao);
  glDeleteBuffers(1, &elements);
  glDeleteBuffers(1, &commands);
  glDeleteProgram(program);
}

// A draw that samples a texture attached to the framebuffer it draws into is a feedback loop (undefined on a GPU);
// sampling another target's texture is not.
TEST_F(GlBarrierCheckTest, ADrawSamplingATextureOfItsOwnFramebufferIsAFeedbackLoop) {
  const GLuint program = pointProgram("#version 450 core\nlayout(binding = 0) uniform sampler2D u_in;\nout vec4 c;\n"
                                      "void main() { c = texelFetch(u_in, ivec2(0), 0); }\n",
                                      "copy.frag");
  RenderTarget a(4, 4), b(4, 4);
  GLuint vao = 0;
  glCreateVertexArrays(1, &vao);
  glBindVertexArray(vao);
  glUseProgram(program);
  a.bind();
  glBindTextureUnit(0, b.colorTexture().handle());
  glDrawArrays(GL_POINTS, 0, 1);
  EXPECT_EQ(hazards(), "");
  glBindTextureUnit(0, a.colorTexture().handle());
  glDrawArrays(GL_POINTS, 0, 1);
  EXPECT_NE(hazards().find("glDrawArrays (point.vert + copy.frag) samples texture unit 0, a texture attached to the "
                           "framebuffer it draws into (a feedback loop)"),
            std::string::npos);
  glBindTextureUnit(0, 0);
  glBindVertexArray(0);
  glUseProgram(0);
  glDeleteVertexArrays(1, &vao);
  glDeleteProgram(program);
}

}  // namespace
}  // namespace farfield::gpu
