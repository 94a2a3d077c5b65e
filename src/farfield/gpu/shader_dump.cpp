#include "farfield/gpu/shader_dump.h"

#include <epoxy/gl.h>
#include <unistd.h>

#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>

#include "farfield/gpu/program.h"

namespace farfield::gpu {

std::string dumpedStageName(const std::string& source_name, uint32_t stage) {
  std::string name = source_name;
  for (const std::string suffix : {".glsl", ".vert", ".frag", ".comp"})
    if (name.size() > suffix.size() && name.ends_with(suffix)) name.resize(name.size() - suffix.size());
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-') c = '_';
  return name + (stage == GL_VERTEX_SHADER ? ".vert" : stage == GL_FRAGMENT_SHADER ? ".frag" : ".comp");
}

void dumpLinkedProgram(std::initializer_list<std::pair<uint32_t, const ShaderStageSource*>> stages) {
  static const char* const dir = std::getenv("FF_SHADER_DUMP");
  if (!dir || !*dir) return;
  namespace fs = std::filesystem;
  std::string all;
  for (const auto& [stage, source] : stages) all += std::to_string(stage) + source->name + '\n' + source->source + '\0';
  char hash[17];
  std::snprintf(hash, sizeof hash, "%016zx", std::hash<std::string>{}(all));
  const fs::path target = fs::path(dir) / hash;
  std::error_code ec;
  if (fs::exists(target, ec)) return;
  // Made under a name of this process's, then renamed: another process writing the same program loses the rename
  // (its folder exists) and removes its copy; a reader never sees a folder half written.
  const fs::path temp = fs::path(dir) / (std::string(hash) + ".tmp" + std::to_string(::getpid()));
  fs::create_directories(temp, ec);
  if (ec) return;
  for (const auto& [stage, source] : stages)
    std::ofstream(temp / dumpedStageName(source->name, stage), std::ios::binary) << source->source;
  fs::rename(temp, target, ec);
  if (ec) fs::remove_all(temp, ec);
}

}  // namespace farfield::gpu
