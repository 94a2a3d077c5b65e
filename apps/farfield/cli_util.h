// Argument parsing shared by the subcommands. Each parser throws farfield::Error naming the option and the value.
#pragma once

#include <string>

#include "farfield/core/math.h"

namespace farfield::app {

// "x,y,z" -> Vec3.
Vec3 parseVec3(const std::string& option, const std::string& text);
// "WxH" -> (W, H), each 1..16384.
IVec2 parseSize(const std::string& option, const std::string& text);
// Creates the parent directory of a file path if needed.
void ensureParentDirectory(const std::string& file);

}  // namespace farfield::app
