#include "farfield/gpu/program.h"

#include <epoxy/gl.h>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <initializer_list>
#include <regex>
#include <sstream>
#include <utility>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/gpu/gl_barrier_check.h"
#include "farfield/gpu/shader_dump.h"
#include "farfield/gpu/shader_source.h"

namespace farfield::gpu {
namespace {

// Rewrites a driver's info log so each message starts with "<shader name>:<line>: ". Drivers write the place in
// different ways: Mesa "0:12(5): error: ...", NVIDIA "0(12) : error C1008: ...", others "ERROR: 0:12: ...".
// The first error message comes first so the exception's first line says what went wrong.
std::string formatLog(const std::string& name, const std::string& log) {
  static const std::regex mesa_or_generic(R"(^\s*(?:ERROR:|WARNING:)?\s*\d+:(\d+)(?:\(\d+\))?\s*:\s*(.*)$)");
  static const std::regex nvidia(R"(^\s*\d+\((\d+)\)\s*:\s*(.*)$)");
  std::vector<std::string> lines;
  std::istringstream in(log);
  std::string line;
  int first_error = -1;
  while (std::getline(in, line)) {
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\0')) line.pop_back();
    if (line.empty()) continue;
    std::smatch m;
    std::string formatted;
    if (std::regex_match(line, m, mesa_or_generic) || std::regex_match(line, m, nvidia))
      formatted = name + ":" + m[1].str() + ": " + m[2].str();
    else
      formatted = name + ": " + line;
    if (first_error < 0 && (line.find("error") != std::string::npos || line.find("ERROR") != std::string::npos))
      first_error = int(lines.size());
    lines.push_back(formatted);
  }
  if (lines.empty()) return name + ": compilation failed (the driver gave no log)";
  if (first_error > 0) std::rotate(lines.begin(), lines.begin() + first_error, lines.begin() + first_error + 1);
  std::string out;
  for (size_t i = 0; i < lines.size(); ++i) out += (i ? "\n" : "") + lines[i];
  return out;
}

std::string shaderLog(GLuint shader) {
  GLint length = 0;
  glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
  std::string log(size_t(std::max(length, 1)), '\0');
  glGetShaderInfoLog(shader, GLsizei(log.size()), nullptr, log.data());
  log.resize(std::strlen(log.c_str()));
  return log;
}

GLuint compile(GLenum stage, const ShaderStageSource& source) {
  GLuint shader = glCreateShader(stage);
  nameGlShader(shader, source.name);  // for the barrier check's messages
  const char* text = source.source.c_str();
  const GLint length = GLint(source.source.size());
  glShaderSource(shader, 1, &text, &length);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    const std::string log = shaderLog(shader);
    glDeleteShader(shader);
    throw Error(formatLog(source.name, log));
  }
  return shader;
}

// Inserts `defines` after the #version line and restores the file's line numbering with #line, so messages keep
// pointing at lines of the .glsl file.
std::string withDefines(const std::string& name, std::string_view source, const std::string& defines) {
  std::string text(source);
  if (defines.empty()) return text;
  const size_t version = text.find("#version");
  if (version == std::string::npos) throw Error(name, "no #version line to insert defines after");
  const size_t eol = text.find('\n', version);
  if (eol == std::string::npos) throw Error(name, "nothing after the #version line");
  const int version_line = 1 + int(std::count(text.begin(), text.begin() + std::ptrdiff_t(version), '\n'));
  std::string insert = defines;
  if (insert.back() != '\n') insert += '\n';
  insert += "#line " + std::to_string(version_line + 1) + "\n";
  text.insert(eol + 1, insert);
  return text;
}

}  // namespace

Program Program::fromEmbedded(const std::string& vertex, const std::string& fragment, const std::string& defines) {
  return fromSources({vertex, withDefines(vertex, shaderSource(vertex), defines)},
                     {fragment, withDefines(fragment, shaderSource(fragment), defines)});
}

namespace {

// Links the compiled shaders into a program (the shaders are deleted either way); throws naming `what`.
GLuint link(std::initializer_list<GLuint> shaders, const std::string& what) {
  GLuint handle = glCreateProgram();
  for (GLuint shader : shaders) glAttachShader(handle, shader);
  glLinkProgram(handle);
  for (GLuint shader : shaders) {
    glDetachShader(handle, shader);
    glDeleteShader(shader);
  }
  GLint ok = 0;
  glGetProgramiv(handle, GL_LINK_STATUS, &ok);
  if (!ok) {
    GLint length = 0;
    glGetProgramiv(handle, GL_INFO_LOG_LENGTH, &length);
    std::string log(size_t(std::max(length, 1)), '\0');
    glGetProgramInfoLog(handle, GLsizei(log.size()), nullptr, log.data());
    log.resize(std::strlen(log.c_str()));
    while (!log.empty() && std::isspace(static_cast<unsigned char>(log.back()))) log.pop_back();
    glDeleteProgram(handle);
    throw Error(what, "link failed: " + log);
  }
  return handle;
}

}  // namespace

Program Program::computeFromEmbedded(const std::string& compute, const std::string& defines) {
  const ShaderStageSource source{compute, withDefines(compute, shaderSource(compute), defines)};
  const GLuint cs = compile(GL_COMPUTE_SHADER, source);
  Program program;
  program.handle_ = link({cs}, compute);
  dumpLinkedProgram({{GL_COMPUTE_SHADER, &source}});
  return program;
}

Program Program::fromSources(const ShaderStageSource& vertex, const ShaderStageSource& fragment) {
  GLuint vs = compile(GL_VERTEX_SHADER, vertex);
  GLuint fs = 0;
  try {
    fs = compile(GL_FRAGMENT_SHADER, fragment);
  } catch (...) {
    glDeleteShader(vs);
    throw;
  }
  const GLuint handle = link({vs, fs}, vertex.name + " + " + fragment.name);
  Program program;
  program.handle_ = handle;
  dumpLinkedProgram({{GL_VERTEX_SHADER, &vertex}, {GL_FRAGMENT_SHADER, &fragment}});
  return program;
}

Program::~Program() {
  if (handle_) glDeleteProgram(handle_);
}

Program::Program(Program&& other) noexcept
    : handle_(std::exchange(other.handle_, 0)), locations_(std::move(other.locations_)) {}

Program& Program::operator=(Program&& other) noexcept {
  if (this != &other) {
    if (handle_) glDeleteProgram(handle_);
    handle_ = std::exchange(other.handle_, 0);
    locations_ = std::move(other.locations_);
  }
  return *this;
}

void Program::use() const { glUseProgram(handle_); }

int Program::uniformLocation(const std::string& name) const {
  auto it = locations_.find(name);
  if (it != locations_.end()) return it->second;
  const int location = glGetUniformLocation(handle_, name.c_str());
  locations_.emplace(name, location);
  return location;
}

// Direct state access: no need for the program to be in use.
void Program::set(const std::string& name, int v) const { glProgramUniform1i(handle_, uniformLocation(name), v); }
void Program::set(const std::string& name, uint32_t v) const {
  glProgramUniform1ui(handle_, uniformLocation(name), v);
}
void Program::set(const std::string& name, float v) const { glProgramUniform1f(handle_, uniformLocation(name), v); }
void Program::set(const std::string& name, const Vec3& v) const {
  glProgramUniform3fv(handle_, uniformLocation(name), 1, glm::value_ptr(v));
}
void Program::set(const std::string& name, const Vec4& v) const {
  glProgramUniform4fv(handle_, uniformLocation(name), 1, glm::value_ptr(v));
}
void Program::set(const std::string& name, const Mat4& v) const {
  glProgramUniformMatrix4fv(handle_, uniformLocation(name), 1, GL_FALSE, glm::value_ptr(v));
}

}  // namespace farfield::gpu
