// Shared by the barrier check's tests (gl_barrier_check_test.cpp, window_test.cpp): small compute programs compiled
// with the check on, and the hazards it found as one string.
#pragma once

#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <string>

#include "farfield/gpu/gl_barrier_check.h"

namespace farfield::gpu::test {

// A compute program compiled with the check on; the shader is named for the messages.
inline GLuint computeProgram(const std::string& source, const std::string& name) {
  const GLuint shader = glCreateShader(GL_COMPUTE_SHADER);
  nameGlShader(shader, name);
  const char* text = source.c_str();
  glShaderSource(shader, 1, &text, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  EXPECT_EQ(ok, GL_TRUE) << name;
  const GLuint program = glCreateProgram();
  glAttachShader(program, shader);
  glLinkProgram(program);
  glDeleteShader(shader);
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  EXPECT_EQ(ok, GL_TRUE) << name;
  return program;
}

// The calling thread's hazards since the last clear, as one string (empty: none), and a fresh start.
inline std::string takeHazards() {
  std::string all;
  for (const GlBarrierHazard& h : glBarrierHazards()) all += h.message + "\n";
  clearGlBarrierHazards();
  return all;
}

}  // namespace farfield::gpu::test
