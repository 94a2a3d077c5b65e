// Argument parsing shared by the subcommands. Each parser throws farfield::Error naming the option and the value.
#pragma once

#include <string>
#include <vector>

#include "farfield/core/bounds.h"
#include "farfield/core/math.h"

namespace farfield::app {

// "x,y,z" -> Vec3.
Vec3 parseVec3(const std::string& option, const std::string& text);
// "WxH" -> (W, H), each 1..16384.
IVec2 parseSize(const std::string& option, const std::string& text);
// --view-min / --view-max "x,y,z" corners -> the box; both empty -> an empty box (the command's default). Throws for
// one without the other.
// The view space of --view-min/--view-max, or of --around PATH (gen::eyeBounds with --margin); an empty box for none.
Box3 parseViewSpace(const std::string& view_min, const std::string& view_max, const std::string& around = {},
                    float margin_m = 0.0f);
// "a,b,,c" -> {"a", "b", "c"} (empty items dropped).
std::vector<std::string> splitList(const std::string& text);
// Creates the parent directory of a file path if needed.
void ensureParentDirectory(const std::string& file);

}  // namespace farfield::app
