// A copy of every GLSL program the process links, for a second compiler's check (scripts/check_shaders.sh runs the
// Khronos reference front end, glslangValidator, over them). The drivers that run Farfield differ in what they accept:
// the tests compile through Mesa, a GPU session through NVIDIA's compiler, and a program only one of them accepts
// costs a GPU session. Off unless FF_SHADER_DUMP names a folder (`make test` sets it to <build>/shader-dump).
#pragma once

#include <cstdint>
#include <initializer_list>
#include <string>
#include <utility>

namespace farfield::gpu {

struct ShaderStageSource;

// Writes a linked program's stages to $FF_SHADER_DUMP/<hash>/<name>.<vert|frag|comp> (stage: GL_VERTEX_SHADER,
// GL_FRAGMENT_SHADER or GL_COMPUTE_SHADER), once per distinct program; several processes may write into the same
// folder at once. Failures to write are ignored: the copy is a check's input, never the program's.
void dumpLinkedProgram(std::initializer_list<std::pair<uint32_t, const ShaderStageSource*>> stages);

// The file name a stage is written under: the source's name without its .glsl and stage suffixes, characters other
// than letters, digits, '_' and '-' as '_', then the stage's suffix ("mesh.frag.glsl" -> "mesh.frag").
std::string dumpedStageName(const std::string& source_name, uint32_t stage);

}  // namespace farfield::gpu
