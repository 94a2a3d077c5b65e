// The report `farfield import` prints: what was read, imported, skipped (per reason) and written, and how long
// each step took.
#pragma once

#include <string>

#include "farfield/geodata/cityjson_import.h"
#include "farfield/geodata/citygml_import.h"
#include "farfield/geodata/osm_import.h"

namespace farfield::app {

struct ImportRun {
  std::string input, output;
  std::string streets_path;  // the street graph written next to the scene (empty: none)
  double write_s = 0.0, total_s = 0.0;
};

void printOsmReport(const ImportRun& run, const geodata::OsmCity& c, const geodata::OsmImportOptions& options,
                    const std::string& objects);
void printCityJsonReport(const ImportRun& run, const geodata::CityJsonScene& c);
void printCityGmlReport(const ImportRun& run, const geodata::CityGmlScene& c);

}  // namespace farfield::app
