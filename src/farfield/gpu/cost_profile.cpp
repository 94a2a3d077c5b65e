#include "farfield/gpu/cost_profile.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>

#include "farfield/core/checked_cast.h"
#include "farfield/core/error.h"

namespace farfield::gpu {

namespace {

double number(const nlohmann::json& j, const char* key, const std::string& source, double lo) {
  if (!j.contains(key)) throw Error(source, std::string("missing key \"") + key + "\"");
  const nlohmann::json& v = j.at(key);
  if (!v.is_number()) throw Error(source, std::string("\"") + key + "\" must be a number");
  const double d = v.get<double>();
  if (!std::isfinite(d) || d < lo)
    throw Error(source, std::string("\"") + key + "\" = " + std::to_string(d) + " is below " + std::to_string(lo));
  return d;
}

void onlyKeys(const nlohmann::json& j, const std::set<std::string>& keys, const std::string& source) {
  if (!j.is_object()) throw Error(source, "expected a JSON object");
  for (const auto& [key, value] : j.items())
    if (!keys.count(key)) throw Error(source, "unknown key \"" + key + "\"");
  for (const std::string& key : keys)
    if (!j.contains(key)) throw Error(source, "missing key \"" + key + "\"");
}

}  // namespace

nlohmann::json CostProfile::toJson() const {
  return {{"format", kCostProfileFormat}, {"version", kCostProfileVersion}, {"model", model.toJson()},
          {"safety_factor", safety_factor}, {"width", width}, {"height", height}, {"fov_y_deg", fov_y_deg},
          {"renderer", renderer}, {"validation", validation}};
}

CostProfile CostProfile::fromJson(const nlohmann::json& j, const std::string& source) {
  onlyKeys(j, {"format", "version", "model", "safety_factor", "width", "height", "fov_y_deg", "renderer", "validation"},
           source);
  if (j.at("format") != kCostProfileFormat)
    throw Error(source, std::string("\"format\" is not \"") + kCostProfileFormat + "\"");
  if (j.at("version") != kCostProfileVersion)
    throw Error(source, "version " + j.at("version").dump() + " (this build reads version " +
                            std::to_string(kCostProfileVersion) + ")");
  CostProfile p;
  const nlohmann::json& m = j.at("model");
  const std::string ms = source + ": model";
  onlyKeys(m, {"base_ms", "ms_per_mtriangle", "ms_per_draw", "ms_per_mpixel", "samples", "rms_error_ms", "r2"}, ms);
  p.model.base_ms = number(m, "base_ms", ms, 0.0);
  p.model.ms_per_mtriangle = number(m, "ms_per_mtriangle", ms, 0.0);
  p.model.ms_per_draw = number(m, "ms_per_draw", ms, 0.0);
  p.model.ms_per_mpixel = number(m, "ms_per_mpixel", ms, 0.0);
  p.model.samples = wholeNumber<size_t>(number(m, "samples", ms, 0.0), ms, "\"samples\"");
  p.model.rms_error_ms = number(m, "rms_error_ms", ms, 0.0);
  p.model.r2 = number(m, "r2", ms, -1e300);
  p.safety_factor = number(j, "safety_factor", source, 1.0);
  // The frame size: whole pixels of an int (a conversion of 1e300 to int is undefined behaviour).
  p.width = wholeNumber<int>(number(j, "width", source, 1.0), source, "\"width\"");
  p.height = wholeNumber<int>(number(j, "height", source, 1.0), source, "\"height\"");
  p.fov_y_deg = number(j, "fov_y_deg", source, 1e-3);
  if (!j.at("renderer").is_string()) throw Error(source, "\"renderer\" must be a string");
  p.renderer = j.at("renderer").get<std::string>();
  p.validation = j.at("validation");
  return p;
}

void saveCostProfile(const CostProfile& profile, const std::string& path) {
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent);
  std::ofstream out(path);
  if (!out) throw Error(path, "cannot write the cost profile");
  out << profile.toJson().dump(2) << "\n";
  if (!out) throw Error(path, "write failed");
}

CostProfile loadCostProfile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error(path, "cannot read the cost profile (write one with farfield calibrate -o " + path + ")");
  nlohmann::json j;
  try {
    in >> j;
  } catch (const nlohmann::json::exception& e) {
    throw Error(path, std::string("not valid JSON: ") + e.what());
  }
  return CostProfile::fromJson(j, path);
}

}  // namespace farfield::gpu
