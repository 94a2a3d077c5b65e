// Reading OpenStreetMap tag values that Farfield uses: lengths with units ("12 m", "40 ft", "12'6\""), level
// counts, building heights (height, building:levels, roof:levels, min_height, building:min_level) and the highway
// classes of the street graph (selection, width and street class).
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace farfield::geodata {

// A length in metres: a plain number ("12", "12.5", "12,5"), a number with a unit ("12 m", "12m", "12 metres",
// "1.2 km", "40 ft", "40'", "12'6\"", "12 ft 6 in"). nullopt for anything else, for negative or non-finite values
// and for values above 2000 m (no building or street is taller or wider).
std::optional<double> parseLength(std::string_view text);
// A level count: a non-negative number ("3", "3.5"); lists ("3;4") take the largest. nullopt otherwise or > 500.
std::optional<double> parseLevels(std::string_view text);

enum class HeightSource { Height, Levels, Default };

struct HeightOptions {
  float level_height = 3.0f;     // metres per building:levels / roof:levels / building:min_level
  float default_height = 10.0f;  // buildings without height or levels (documented in the import report)
};

struct BuildingHeight {
  double base = 0.0;    // bottom of the walls above the ground: min_height, else building:min_level x level height
  double top = 0.0;     // top of the building above the ground: height, else (building:levels + roof:levels) x
                        // level height, else base + default height
  HeightSource source = HeightSource::Default;
  bool bad_value = false;  // a height/level tag was present but unreadable (the next source was used)
};

// Tag lookup: the value of a key or nullptr.
using TagLookup = std::function<const char*(const char* key)>;

// Heights of a building or building:part from its tags. top > base always holds: when the tags give a top at or
// below the base, top = base + one level height (and bad_value is set).
BuildingHeight buildingHeight(const TagLookup& tags, const HeightOptions& options = {});

// Highway classes of the street graph.
struct HighwayClass {
  std::string name;      // value of the highway tag ("primary")
  float width = 10.0f;   // default carriageway width, metres (a `width` tag overrides it)
  int street_class = 1;  // urban::StreetClass: 0 avenue, 1 street, 2 lane
};
// Every highway value Farfield knows, with widths and classes; the default selection is the vehicle roads (motorway
// to living_street and their links, pedestrian streets).
const std::vector<HighwayClass>& knownHighwayClasses();
std::vector<std::string> defaultHighwaySelection();
// nullptr for an unknown value.
const HighwayClass* findHighwayClass(std::string_view value);

}  // namespace farfield::geodata
