// GLSL sources embedded at build time from src/farfield/gpu/shaders (cmake/EmbedShaders.cmake).
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace farfield::gpu {

// Source of an embedded shader by file name ("mesh.vert.glsl"); FF_CHECK-fails for an unknown name (a bug).
std::string_view shaderSource(const std::string& name);
std::vector<std::string> shaderNames();

}  // namespace farfield::gpu
