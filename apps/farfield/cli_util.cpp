#include "cli_util.h"

#include <charconv>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/gen/camera_path.h"

namespace farfield::app {
namespace {

bool parseFloat(const std::string& s, float& out) {
  const char* begin = s.data();
  const char* end = s.data() + s.size();
  while (begin < end && *begin == ' ') ++begin;
  auto [ptr, ec] = std::from_chars(begin, end, out);
  return ec == std::errc() && ptr == end && std::isfinite(out);
}

}  // namespace

Vec3 parseVec3(const std::string& option, const std::string& text) {
  std::vector<std::string> parts;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');) parts.push_back(item);
  Vec3 v;
  if (parts.size() != 3 || !parseFloat(parts[0], v.x) || !parseFloat(parts[1], v.y) || !parseFloat(parts[2], v.z))
    throw Error(option, "expected three finite numbers 'x,y,z', got '" + text + "'");
  return v;
}

Box3 parseViewSpace(const std::string& view_min, const std::string& view_max, const std::string& around,
                    float margin_m) {
  if (view_min.empty() != view_max.empty())
    throw Error("--view-min/--view-max", "give both corners of the view space, or neither");
  if (!around.empty()) {
    if (!view_min.empty()) throw Error("--around", "give either --around or --view-min/--view-max, not both");
    return gen::eyeBounds(gen::loadCameraPath(around), margin_m, around);
  }
  if (view_min.empty()) return Box3{};
  return Box3::fromPoints(parseVec3("--view-min", view_min), parseVec3("--view-max", view_max));
}

std::vector<std::string> splitList(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

IVec2 parseSize(const std::string& option, const std::string& text) {
  const auto x = text.find('x');
  int w = 0, h = 0;
  auto parseInt = [](const std::string& s, int& out) {
    auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
    return !s.empty() && ec == std::errc() && ptr == s.data() + s.size();
  };
  if (x == std::string::npos || !parseInt(text.substr(0, x), w) || !parseInt(text.substr(x + 1), h) || w < 1 ||
      h < 1 || w > 16384 || h > 16384)
    throw Error(option, "expected an image size 'WxH' with W and H in 1..16384, got '" + text + "'");
  return {w, h};
}

void ensureParentDirectory(const std::string& file) {
  const auto parent = std::filesystem::path(file).parent_path();
  if (parent.empty()) return;
  std::error_code ec;
  std::filesystem::create_directories(parent, ec);
  if (ec) throw Error(file, "cannot create directory '" + parent.string() + "': " + ec.message());
}

}  // namespace farfield::app
