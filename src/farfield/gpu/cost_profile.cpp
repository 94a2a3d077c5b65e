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

// `with_fill`: version 3 and later have the fill term; earlier profiles are read with it at 0.
CostModel modelFromJson(const nlohmann::json& m, const std::string& ms, bool with_fill) {
  std::set<std::string> keys{"base_ms", "ms_per_mtriangle", "ms_per_draw", "ms_per_mpixel", "samples", "rms_error_ms",
                             "r2"};
  if (with_fill) keys.insert({"ms_per_mfill", "fill_cap_pixels"});
  onlyKeys(m, keys, ms);
  CostModel model;
  model.base_ms = number(m, "base_ms", ms, 0.0);
  model.ms_per_mtriangle = number(m, "ms_per_mtriangle", ms, 0.0);
  model.ms_per_draw = number(m, "ms_per_draw", ms, 0.0);
  model.ms_per_mpixel = number(m, "ms_per_mpixel", ms, 0.0);
  if (with_fill) {
    model.ms_per_mfill = number(m, "ms_per_mfill", ms, 0.0);
    model.fill_cap_pixels = number(m, "fill_cap_pixels", ms, 0.0);
  }
  model.samples = wholeNumber<size_t>(number(m, "samples", ms, 0.0), ms, "\"samples\"");
  model.rms_error_ms = number(m, "rms_error_ms", ms, 0.0);
  model.r2 = number(m, "r2", ms, -1e300);
  return model;
}

}  // namespace

nlohmann::json LayeredCost::toJson() const {
  if (!calibrated) return nullptr;
  return {{"draw", draw.toJson()}, {"capture", capture.toJson()}, {"draw_safety_factor", draw_safety_factor},
          {"capture_safety_factor", capture_safety_factor}, {"validation", validation}};
}

LayeredCost LayeredCost::fromJson(const nlohmann::json& j, const std::string& source, int version) {
  LayeredCost c;
  if (j.is_null()) return c;
  onlyKeys(j, {"draw", "capture", "draw_safety_factor", "capture_safety_factor", "validation"}, source);
  c.calibrated = true;
  c.draw = modelFromJson(j.at("draw"), source + ".draw", version >= 3);
  c.capture = modelFromJson(j.at("capture"), source + ".capture", version >= 3);
  c.draw_safety_factor = number(j, "draw_safety_factor", source, 1.0);
  c.capture_safety_factor = number(j, "capture_safety_factor", source, 1.0);
  c.validation = j.at("validation");
  return c;
}

nlohmann::json CostProfile::toJson() const {
  return {{"format", kCostProfileFormat}, {"version", kCostProfileVersion}, {"model", model.toJson()},
          {"safety_factor", safety_factor},
          {"safety_margin_ms", std::isfinite(safety_margin_ms) ? nlohmann::json(safety_margin_ms) : nlohmann::json()},
          {"width", width}, {"height", height}, {"fov_y_deg", fov_y_deg},
          {"renderer", renderer}, {"validation", validation}, {"layered", layered.toJson()}};
}

CostProfile CostProfile::fromJson(const nlohmann::json& j, const std::string& source) {
  // Version 1 has no "layered" key; later versions must have it. Versions 1 and 2 have no fill term.
  const nlohmann::json* v = j.is_object() && j.contains("version") ? &j.at("version") : nullptr;
  const int version = v && v->is_number_integer() ? v->get<int>() : 0;  // 0: none this build reads
  std::set<std::string> keys{"format", "version", "model", "safety_factor", "width", "height", "fov_y_deg",
                             "renderer", "validation"};
  if (version != 1) keys.insert("layered");
  if (version >= 4) keys.insert("safety_margin_ms");
  onlyKeys(j, keys, source);
  if (j.at("format") != kCostProfileFormat)
    throw Error(source, std::string("\"format\" is not \"") + kCostProfileFormat + "\"");
  if (version < 1 || version > kCostProfileVersion)
    throw Error(source, "version " + j.at("version").dump() + " (this build reads versions 1 to " +
                            std::to_string(kCostProfileVersion) + ")");
  CostProfile p;
  p.model = modelFromJson(j.at("model"), source + ": model", version >= 3);
  if (version != 1) p.layered = LayeredCost::fromJson(j.at("layered"), source + ": layered", version);
  p.safety_factor = number(j, "safety_factor", source, 1.0);
  if (version >= 4 && !j.at("safety_margin_ms").is_null())
    p.safety_margin_ms = number(j, "safety_margin_ms", source, 0.0);
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
