#include "farfield/gpu/shader_source.h"

#include <map>

#include "farfield/core/check.h"

namespace farfield::gpu {
namespace detail {
const std::map<std::string, std::string_view>& embeddedShaders();  // generated (cmake/embed_shaders_script.cmake)
}

std::string_view shaderSource(const std::string& name) {
  const auto& shaders = detail::embeddedShaders();
  auto it = shaders.find(name);
  FF_CHECK_MSG(it != shaders.end(), name.c_str());
  return it->second;
}

std::vector<std::string> shaderNames() {
  std::vector<std::string> names;
  for (const auto& [name, source] : detail::embeddedShaders()) names.push_back(name);
  return names;
}

}  // namespace farfield::gpu
