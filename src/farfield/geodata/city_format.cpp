#include "farfield/geodata/city_format.h"

#include <algorithm>
#include <cctype>

#include "farfield/core/error.h"

namespace farfield::geodata {

CityFormat cityFormatFromName(const std::string& path) {
  std::string name = path;
  std::transform(name.begin(), name.end(), name.begin(), [](unsigned char ch) { return char(std::tolower(ch)); });
  auto ends = [&](const std::string& ext) {
    return name.size() > ext.size() && name.compare(name.size() - ext.size(), ext.size(), ext) == 0;
  };
  if (ends(".gml") || ends(".citygml") || ends(".xml")) return CityFormat::CityGml;
  if (ends(".json") || ends(".cityjson")) return CityFormat::CityJson;
  if (ends(".pbf") || ends(".osm")) return CityFormat::Osm;
  throw Error(path, "unknown city format (expected .osm.pbf, .osm, .city.json, .gml or .citygml; or name the "
                    "format: farfield import osm|cityjson|citygml)");
}

}  // namespace farfield::geodata
