// GLSL program (vertex and fragment, or compute) from embedded or given sources. Compile and link errors throw farfield::Error naming the shader and
// the line of the error.
#pragma once

#include <cstdint>
#include <string>
#include <unordered_map>

#include "farfield/core/math.h"

namespace farfield::gpu {

struct ShaderStageSource {
  std::string name;    // for messages, e.g. "mesh.vert.glsl"
  std::string source;
};

class Program {
 public:
  Program() = default;
  // From embedded shader names (shaderSource); defines are inserted after the #version line ("#define X 1").
  static Program fromEmbedded(const std::string& vertex, const std::string& fragment, const std::string& defines = "");
  static Program fromSources(const ShaderStageSource& vertex, const ShaderStageSource& fragment);
  // A compute program from an embedded shader.
  static Program computeFromEmbedded(const std::string& compute, const std::string& defines = "");
  ~Program();
  Program(Program&& other) noexcept;
  Program& operator=(Program&& other) noexcept;
  Program(const Program&) = delete;
  Program& operator=(const Program&) = delete;

  void use() const;
  uint32_t handle() const { return handle_; }
  int uniformLocation(const std::string& name) const;  // -1 if absent (cached)
  void set(const std::string& name, int v) const;
  void set(const std::string& name, uint32_t v) const;
  void set(const std::string& name, float v) const;
  void set(const std::string& name, const Vec3& v) const;
  void set(const std::string& name, const Vec4& v) const;
  void set(const std::string& name, const Mat4& v) const;

 private:
  uint32_t handle_ = 0;
  mutable std::unordered_map<std::string, int> locations_;
};

}  // namespace farfield::gpu
