// The format of a city file from its name, for commands and programs that take any city file.
#pragma once

#include <string>

namespace farfield::geodata {

enum class CityFormat { Osm, CityJson, CityGml };

// .osm.pbf / .pbf / .osm -> Osm; .city.json / .json / .cityjson -> CityJson; .gml / .citygml / .xml -> CityGml (case
// does not matter). Throws farfield::Error naming the file for any other name.
CityFormat cityFormatFromName(const std::string& path);

}  // namespace farfield::geodata
