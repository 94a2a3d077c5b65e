// The tileset checks (see the header). Volumes are taken to the root's frame: a box as its centre and three half-axis
// vectors, a sphere as centre and radius (scaled by the largest column of the transform), so containment is a test of
// the child's corners (or its sphere) against the parent's volume.
#include "farfield/store/export_tiles_check.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "farfield/core/error.h"
#include "farfield/core/math.h"

namespace farfield::store {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct Volume {
  bool box = true;
  DVec3 centre{0.0};
  DVec3 axes[3] = {DVec3(0.0), DVec3(0.0), DVec3(0.0)};  // box half axes
  double radius = 0.0;                                     // sphere
  double size() const {
    return box ? glm::length(axes[0]) + glm::length(axes[1]) + glm::length(axes[2]) : radius;
  }
};

bool finiteNumbers(const json& j, size_t n) {
  if (!j.is_array() || j.size() != n) return false;
  for (const json& v : j)
    if (!v.is_number() || !std::isfinite(v.get<double>())) return false;
  return true;
}

DMat4 matrixFrom(const json& j) {
  DMat4 m(1.0);
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) m[c][r] = j[size_t(c * 4 + r)].get<double>();
  return m;
}

std::vector<DVec3> corners(const Volume& v) {
  std::vector<DVec3> out;
  for (int i = 0; i < 8; ++i)
    out.push_back(v.centre + ((i & 1) ? 1.0 : -1.0) * v.axes[0] + ((i & 2) ? 1.0 : -1.0) * v.axes[1] +
                  ((i & 4) ? 1.0 : -1.0) * v.axes[2]);
  return out;
}

// How far (metres) p lies outside the volume (<= 0 inside). A box's zero axes (a flat box) are completed with
// orthogonal axes of zero length, whose coordinate must then be zero.
double outside(const Volume& v, const DVec3& p) {
  if (!v.box) return glm::length(p - v.centre) - v.radius;
  double worst = -std::numeric_limits<double>::infinity();
  const DVec3 d = p - v.centre;
  for (int i = 0; i < 3; ++i) {
    const double len = glm::length(v.axes[i]);
    DVec3 dir;
    if (len > 1e-12) {
      dir = v.axes[i] / len;
    } else {
      // Orthogonal to the other (non-zero) axes.
      const DVec3 a = v.axes[(i + 1) % 3], b = v.axes[(i + 2) % 3];
      dir = glm::cross(a, b);
      if (glm::length(dir) < 1e-12) dir = glm::cross(glm::length(a) > 1e-12 ? a : b, DVec3(0.577, 0.577, 0.578));
      if (glm::length(dir) < 1e-12) dir = DVec3(1, 0, 0);
      dir = glm::normalize(dir);
    }
    // Axes of a box are orthogonal: the coordinate along the unit axis against the half length.
    worst = std::max(worst, std::abs(glm::dot(d, dir)) - len);
  }
  return worst;
}

double childOutside(const Volume& parent, const Volume& child) {
  if (child.box) {
    double worst = -std::numeric_limits<double>::infinity();
    for (const DVec3& c : corners(child)) worst = std::max(worst, outside(parent, c));
    return worst;
  }
  if (!parent.box) return glm::length(child.centre - parent.centre) + child.radius - parent.radius;
  return outside(parent, child.centre) + child.radius;
}

class Checker {
 public:
  explicit Checker(std::string path) : path_(std::move(path)), dir_(fs::path(path_).parent_path()) {}

  std::vector<std::string> run() {
    std::ifstream in(path_);
    if (!in) return {path_ + ": cannot be read"};
    json ts;
    try {
      in >> ts;
    } catch (const std::exception& e) {
      return {path_ + ": not JSON: " + e.what()};
    }
    if (!ts.is_object()) return {path_ + ": not a JSON object"};
    const json* asset = ts.contains("asset") ? &ts["asset"] : nullptr;
    if (!asset || !asset->is_object())
      problem("asset", "missing (required: an object with \"version\")");
    else if (!asset->contains("version") || !(*asset)["version"].is_string())
      problem("asset.version", "missing or not a string");
    else if ((*asset)["version"] != "1.0" && (*asset)["version"] != "1.1")
      problem("asset.version", "is \"" + (*asset)["version"].get<std::string>() + "\", expected \"1.0\" or \"1.1\"");
    std::optional<double> top_error = errorOf(ts, "geometricError (top level)");
    if (!ts.contains("root") || !ts["root"].is_object()) {
      problem("root", "missing (required: the root tile)");
      return problems_;
    }
    const json& root = ts["root"];
    if (!root.contains("refine")) problem("root.refine", "missing (required on the root: \"ADD\" or \"REPLACE\")");
    const std::optional<double> root_error = errorOf(root, "root.geometricError");
    if (top_error && root_error && *top_error < *root_error)
      problem("geometricError", "the tileset's " + num(*top_error) + " is below the root tile's " + num(*root_error));
    visit(root, "root", DMat4(1.0), nullptr, root_error);
    return problems_;
  }

 private:
  static std::string num(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
  }

  void problem(const std::string& where, const std::string& what) { problems_.push_back(path_ + ": " + where + ": " + what); }

  std::optional<double> errorOf(const json& tile, const std::string& where) {
    if (!tile.contains("geometricError") || !tile["geometricError"].is_number()) {
      problem(where, "missing or not a number");
      return std::nullopt;
    }
    const double e = tile["geometricError"].get<double>();
    if (!std::isfinite(e) || e < 0.0) {
      problem(where, "is " + num(e) + ", expected a finite number >= 0");
      return std::nullopt;
    }
    return e;
  }

  std::optional<Volume> volumeOf(const json& tile, const std::string& where, const DMat4& m) {
    if (!tile.contains("boundingVolume") || !tile["boundingVolume"].is_object()) {
      problem(where + ".boundingVolume", "missing");
      return std::nullopt;
    }
    const json& bv = tile["boundingVolume"];
    Volume v;
    if (bv.contains("box")) {
      if (!finiteNumbers(bv["box"], 12)) {
        problem(where + ".boundingVolume.box", "must be 12 finite numbers");
        return std::nullopt;
      }
      const json& b = bv["box"];
      auto at = [&](size_t i) { return DVec3(b[i].get<double>(), b[i + 1].get<double>(), b[i + 2].get<double>()); };
      v.centre = DVec3(m * glm::dvec4(at(0), 1.0));
      for (int i = 0; i < 3; ++i) v.axes[i] = glm::dmat3(m) * at(size_t(3 + 3 * i));
      return v;
    }
    if (bv.contains("sphere")) {
      if (!finiteNumbers(bv["sphere"], 4) || bv["sphere"][3].get<double>() < 0.0) {
        problem(where + ".boundingVolume.sphere", "must be 4 finite numbers with a radius >= 0");
        return std::nullopt;
      }
      const json& s = bv["sphere"];
      v.box = false;
      v.centre = DVec3(m * glm::dvec4(s[0].get<double>(), s[1].get<double>(), s[2].get<double>(), 1.0));
      const glm::dmat3 l(m);
      v.radius = s[3].get<double>() * std::max({glm::length(l[0]), glm::length(l[1]), glm::length(l[2])});
      return v;
    }
    if (bv.contains("region"))
      problem(where + ".boundingVolume", "a region volume cannot be checked here (boxes and spheres only)");
    else
      problem(where + ".boundingVolume", "has no box, sphere or region");
    return std::nullopt;
  }

  void visit(const json& tile, const std::string& where, const DMat4& parent_frame, const Volume* parent_volume,
             std::optional<double> parent_error) {
    DMat4 frame = parent_frame;
    if (tile.contains("transform")) {
      if (!finiteNumbers(tile["transform"], 16))
        problem(where + ".transform", "must be 16 finite numbers");
      else
        frame = parent_frame * matrixFrom(tile["transform"]);
    }
    if (tile.contains("refine") &&
        (!tile["refine"].is_string() || (tile["refine"] != "ADD" && tile["refine"] != "REPLACE")))
      problem(where + ".refine", "must be \"ADD\" or \"REPLACE\"");
    const std::optional<double> error = where == "root" ? parent_error : errorOf(tile, where + ".geometricError");
    if (error && parent_error && where != "root" && *error > *parent_error)
      problem(where + ".geometricError", num(*error) + " exceeds its parent's " + num(*parent_error));
    const std::optional<Volume> volume = volumeOf(tile, where, frame);
    if (volume && parent_volume) {
      const double tol = 1e-3 + 1e-6 * parent_volume->size();
      const double out = childOutside(*parent_volume, *volume);
      if (out > tol) problem(where + ".boundingVolume", "lies outside its parent's by " + num(out) + " m");
    }
    if (tile.contains("content")) checkContent(tile["content"], where + ".content", frame, volume);
    if (tile.contains("contents")) {
      if (!tile["contents"].is_array())
        problem(where + ".contents", "must be an array");
      else
        for (size_t i = 0; i < tile["contents"].size(); ++i)
          checkContent(tile["contents"][i], where + ".contents[" + std::to_string(i) + "]", frame, volume);
    }
    if (tile.contains("children")) {
      const json& children = tile["children"];
      if (!children.is_array()) {
        problem(where + ".children", "must be an array");
        return;
      }
      for (size_t i = 0; i < children.size(); ++i) {
        const std::string w = where + ".children[" + std::to_string(i) + "]";
        if (!children[i].is_object())
          problem(w, "is not a tile object");
        else
          visit(children[i], w, frame, volume ? &*volume : nullptr, error);
      }
    }
  }

  void checkContent(const json& content, const std::string& where, const DMat4& frame,
                    const std::optional<Volume>& volume) {
    if (!content.is_object() || !content.contains("uri") || !content["uri"].is_string()) {
      problem(where, "has no \"uri\" string");
      return;
    }
    const std::string uri = content["uri"].get<std::string>();
    if (uri.find("://") != std::string::npos) {
      problem(where + ".uri", "'" + uri + "' is not a local file (cannot be resolved here)");
      return;
    }
    const fs::path file = dir_ / uri;
    if (!fs::is_regular_file(file)) {
      problem(where + ".uri", "'" + uri + "' does not resolve: " + file.string() + " is not a file");
      return;
    }
    if (file.extension() == ".glb" && volume) checkGlb(file.string(), where, frame, *volume);
  }

  // The glb's meshes, through node matrices and the y-up to z-up turn, inside the tile's volume.
  void checkGlb(const std::string& file, const std::string& where, const DMat4& frame, const Volume& volume) {
    std::ifstream in(file, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    auto u32 = [&](size_t off) {
      uint32_t v = 0;
      std::memcpy(&v, bytes.data() + off, 4);
      return v;
    };
    if (bytes.size() < 20 || u32(0) != 0x46546C67u || u32(4) != 2 || u32(8) != bytes.size() ||
        u32(16) != 0x4E4F534Au || size_t(u32(12)) + 20 > bytes.size()) {
      problem(where, file + " is not a glTF 2.0 binary (header, length or JSON chunk)");
      return;
    }
    json gltf;
    try {
      gltf = json::parse(bytes.substr(20, u32(12)));
    } catch (const std::exception& e) {
      problem(where, file + ": glTF JSON chunk does not parse: " + e.what());
      return;
    }
    // glTF content is Y up; 3D Tiles turns it Z up before the tile's transform (rows (1,0,0), (0,0,-1), (0,1,0)).
    const DMat4 y_up_to_z_up(glm::dvec4(1, 0, 0, 0), glm::dvec4(0, 0, 1, 0), glm::dvec4(0, -1, 0, 0), glm::dvec4(0, 0, 0, 1));
    const double tol = 1e-3 + 1e-6 * volume.size();
    double worst = -std::numeric_limits<double>::infinity();
    try {
      const json& nodes = gltf.value("nodes", json::array());
      const size_t scene = gltf.value("scene", 0);
      if (!gltf.contains("scenes") || scene >= gltf["scenes"].size()) return;
      std::vector<std::pair<size_t, DMat4>> stack;
      for (const json& n : gltf["scenes"][scene].value("nodes", json::array()))
        stack.emplace_back(n.get<size_t>(), frame * y_up_to_z_up);
      size_t visited = 0;
      while (!stack.empty() && visited++ < 1000000) {
        auto [index, parent] = stack.back();
        stack.pop_back();
        const json& node = nodes.at(index);
        DMat4 local(1.0);
        if (node.contains("matrix")) {
          local = matrixFrom(node["matrix"]);
        } else {
          const json t = node.value("translation", json::array({0, 0, 0}));
          const json r = node.value("rotation", json::array({0, 0, 0, 1}));
          const json s = node.value("scale", json::array({1, 1, 1}));
          const glm::dquat q(r[3].get<double>(), r[0].get<double>(), r[1].get<double>(), r[2].get<double>());
          local = glm::translate(DMat4(1.0), DVec3(t[0].get<double>(), t[1].get<double>(), t[2].get<double>())) *
                  glm::mat4_cast(q) *
                  glm::scale(DMat4(1.0), DVec3(s[0].get<double>(), s[1].get<double>(), s[2].get<double>()));
        }
        const DMat4 m = parent * local;
        if (node.contains("mesh"))
          for (const json& prim : gltf.at("meshes").at(node["mesh"].get<size_t>()).at("primitives")) {
            const json& acc = gltf.at("accessors").at(prim.at("attributes").at("POSITION").get<size_t>());
            const json& lo = acc.at("min");
            const json& hi = acc.at("max");
            for (int i = 0; i < 8; ++i) {
              const DVec3 p((i & 1) ? hi[0].get<double>() : lo[0].get<double>(),
                            (i & 2) ? hi[1].get<double>() : lo[1].get<double>(),
                            (i & 4) ? hi[2].get<double>() : lo[2].get<double>());
              worst = std::max(worst, outside(volume, DVec3(m * glm::dvec4(p, 1.0))));
            }
          }
        for (const json& c : node.value("children", json::array())) stack.emplace_back(c.get<size_t>(), m);
      }
    } catch (const std::exception& e) {
      problem(where, file + ": glTF nodes, meshes or POSITION min/max unreadable: " + e.what());
      return;
    }
    if (worst > tol)
      problem(where, file + ": content lies outside the tile's bounding volume by " + num(worst) + " m");
  }

  std::string path_;
  fs::path dir_;
  std::vector<std::string> problems_;
};

}  // namespace

std::vector<std::string> checkTileset(const std::string& tileset_path) { return Checker(tileset_path).run(); }

void requireValidTileset(const std::string& tileset_path) {
  const std::vector<std::string> problems = checkTileset(tileset_path);
  if (problems.empty()) return;
  std::string text = std::to_string(problems.size()) + " problem(s) with the tileset:";
  for (size_t i = 0; i < problems.size() && i < 5; ++i) text += "\n  " + problems[i];
  throw Error(tileset_path, text);
}

}  // namespace farfield::store
