// OSM tag values. The wiki's conventions (https://wiki.openstreetmap.org/wiki/Key:height): metres by default,
// explicit units after a space, feet and inches as 12'6". Mappers also write "12m", "12 metres" and decimal
// commas; these are accepted because dropping them would only push the building down to the level count or the
// default height.
#include "farfield/geodata/osm_tags.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>

namespace farfield::geodata {

namespace {

constexpr double kMaxLength = 2000.0;
constexpr double kFoot = 0.3048;
constexpr double kInch = 0.0254;

std::string_view trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

// Reads an unsigned decimal number ("12", "12.5", ".5", "12,5") from the front of s; advances s.
std::optional<double> readNumber(std::string_view& s) {
  std::string digits;
  size_t i = 0;
  bool seen_digit = false, seen_point = false;
  for (; i < s.size(); ++i) {
    const char c = s[i];
    if (std::isdigit(static_cast<unsigned char>(c))) {
      digits += c;
      seen_digit = true;
    } else if ((c == '.' || c == ',') && !seen_point && i + 1 < s.size() &&
               std::isdigit(static_cast<unsigned char>(s[i + 1]))) {
      digits += '.';
      seen_point = true;
    } else {
      break;
    }
  }
  if (!seen_digit) return std::nullopt;
  s.remove_prefix(i);
  char* end = nullptr;
  const double v = std::strtod(digits.c_str(), &end);
  if (end != digits.c_str() + digits.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

bool lowerEquals(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(a[i])) != b[i]) return false;
  return true;
}

std::optional<double> unitFactor(std::string_view unit) {
  unit = trim(unit);
  if (unit.empty()) return 1.0;
  for (const char* m : {"m", "meter", "meters", "metre", "metres"})
    if (lowerEquals(unit, m)) return 1.0;
  for (const char* k : {"km", "kilometer", "kilometers", "kilometre", "kilometres"})
    if (lowerEquals(unit, k)) return 1000.0;
  for (const char* c : {"cm"})
    if (lowerEquals(unit, c)) return 0.01;
  for (const char* f : {"ft", "feet", "foot", "'"})
    if (lowerEquals(unit, f)) return kFoot;
  for (const char* in : {"in", "inch", "inches", "\""})
    if (lowerEquals(unit, in)) return kInch;
  return std::nullopt;
}

}  // namespace

std::optional<double> parseLength(std::string_view text) {
  std::string_view s = trim(text);
  if (s.empty()) return std::nullopt;
  if (s.front() == '+') s.remove_prefix(1);
  std::optional<double> first = readNumber(s);
  if (!first) return std::nullopt;
  s = trim(s);
  double value = 0.0;
  // Feet and inches: 12'6" or 12 ft 6 in.
  auto try_feet_inches = [&](std::string_view rest) -> std::optional<double> {
    std::string_view r = trim(rest);
    std::optional<double> inches = readNumber(r);
    if (!inches) return std::nullopt;
    r = trim(r);
    if (r == "\"" || lowerEquals(r, "in") || lowerEquals(r, "inch") || lowerEquals(r, "inches"))
      return *first * kFoot + *inches * kInch;
    return std::nullopt;
  };
  if (!s.empty() && s.front() == '\'') {
    std::string_view rest = s.substr(1);
    if (trim(rest).empty()) {
      value = *first * kFoot;
    } else if (auto v = try_feet_inches(rest)) {
      value = *v;
    } else {
      return std::nullopt;
    }
  } else if (s.size() >= 2 && (lowerEquals(s.substr(0, 2), "ft")) && s.size() > 2 && !std::isalpha(static_cast<unsigned char>(s[2]))) {
    auto v = try_feet_inches(s.substr(2));
    if (!v) return std::nullopt;
    value = *v;
  } else {
    std::optional<double> factor = unitFactor(s);
    if (!factor) return std::nullopt;
    value = *first * *factor;
  }
  if (!std::isfinite(value) || value < 0.0 || value > kMaxLength) return std::nullopt;
  return value;
}

std::optional<double> parseLevels(std::string_view text) {
  std::string_view s = trim(text);
  std::optional<double> best;
  while (!s.empty()) {
    const size_t semi = s.find(';');
    std::string_view item = trim(s.substr(0, semi));
    std::optional<double> v = readNumber(item);
    if (!v || !trim(item).empty()) return std::nullopt;
    if (!best || *v > *best) best = v;
    if (semi == std::string_view::npos) break;
    s = s.substr(semi + 1);
  }
  if (!best || *best > 500.0) return std::nullopt;
  return best;
}

BuildingHeight buildingHeight(const TagLookup& tags, const HeightOptions& options) {
  BuildingHeight h;
  const double level = options.level_height;
  auto length_of = [&](const char* key) -> std::optional<double> {
    const char* v = tags(key);
    if (!v) return std::nullopt;
    auto parsed = parseLength(v);
    if (!parsed) h.bad_value = true;
    return parsed;
  };
  auto levels_of = [&](const char* key) -> std::optional<double> {
    const char* v = tags(key);
    if (!v) return std::nullopt;
    auto parsed = parseLevels(v);
    if (!parsed) h.bad_value = true;
    return parsed;
  };

  if (auto min_h = length_of("min_height")) {
    h.base = *min_h;
  } else if (auto min_level = levels_of("building:min_level")) {
    h.base = *min_level * level;
  }

  std::optional<double> top = length_of("height");
  if (!top) top = length_of("building:height");
  if (top) {
    h.source = HeightSource::Height;
    h.top = *top;
  } else {
    std::optional<double> levels = levels_of("building:levels");
    if (levels) {
      std::optional<double> roof_levels = levels_of("roof:levels");
      h.source = HeightSource::Levels;
      h.top = (*levels + roof_levels.value_or(0.0)) * level;
      // Simple 3D Buildings: building:levels counts the levels from the ground up, building:min_level those
      // left out at the bottom, so the top does not depend on the base.
      if (h.top <= 0.0) h.top = level;  // "building:levels=0" (a roof over a car park): one level
    } else {
      h.source = HeightSource::Default;
      h.top = h.base + options.default_height;
    }
  }
  if (!(h.top > h.base)) {
    h.bad_value = true;
    h.top = h.base + level;
  }
  return h;
}

const std::vector<HighwayClass>& knownHighwayClasses() {
  // Widths: typical carriageway plus pavements, metres. Classes: arterials are avenues, ordinary roads streets,
  // everything narrow lanes.
  static const std::vector<HighwayClass> classes = {
      {"motorway", 25.0f, 0},      {"trunk", 22.0f, 0},          {"primary", 18.0f, 0},
      {"secondary", 15.0f, 0},     {"tertiary", 12.0f, 1},       {"unclassified", 10.0f, 1},
      {"residential", 10.0f, 1},   {"living_street", 8.0f, 1},   {"motorway_link", 10.0f, 0},
      {"trunk_link", 10.0f, 0},    {"primary_link", 9.0f, 0},    {"secondary_link", 8.0f, 0},
      {"tertiary_link", 8.0f, 1},  {"pedestrian", 8.0f, 2},      {"service", 6.0f, 2},
      {"road", 10.0f, 1},          {"track", 4.0f, 2},           {"busway", 8.0f, 1},
      {"footway", 3.0f, 2},        {"path", 2.5f, 2},            {"cycleway", 3.0f, 2},
      {"steps", 3.0f, 2},          {"bridleway", 3.0f, 2},       {"corridor", 2.5f, 2},
  };
  return classes;
}

std::vector<std::string> defaultHighwaySelection() {
  return {"motorway",      "trunk",      "primary",      "secondary",      "tertiary",
          "unclassified",  "residential", "living_street", "motorway_link", "trunk_link",
          "primary_link",  "secondary_link", "tertiary_link", "pedestrian"};
}

const HighwayClass* findHighwayClass(std::string_view value) {
  for (const HighwayClass& c : knownHighwayClasses())
    if (c.name == value) return &c;
  return nullptr;
}

}  // namespace farfield::geodata
