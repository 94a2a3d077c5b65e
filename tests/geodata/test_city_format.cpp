// The city format from a file name: every documented extension in any case, and clear errors for the rest.
#include <gtest/gtest.h>

#include "farfield/core/error.h"
#include "farfield/geodata/city_format.h"

using farfield::geodata::CityFormat;
using farfield::geodata::cityFormatFromName;

TEST(CityFormat, FromExtensionInAnyCase) {
  EXPECT_EQ(cityFormatFromName("monaco-2016.osm.pbf"), CityFormat::Osm);
  EXPECT_EQ(cityFormatFromName("dir.gml/x.OSM"), CityFormat::Osm);
  EXPECT_EQ(cityFormatFromName("delft.city.json"), CityFormat::CityJson);
  EXPECT_EQ(cityFormatFromName("a.CityJSON"), CityFormat::CityJson);
  EXPECT_EQ(cityFormatFromName("berlin.GML"), CityFormat::CityGml);
  EXPECT_EQ(cityFormatFromName("x.citygml"), CityFormat::CityGml);
  EXPECT_EQ(cityFormatFromName("x.xml"), CityFormat::CityGml);
}

TEST(CityFormat, UnknownNamesAreErrorsNamingTheFile) {
  for (const char* name : {"city.obj", "city", ".gml", "json", "x.pbf.gz"}) {
    try {
      cityFormatFromName(name);
      ADD_FAILURE() << name << " was accepted";
    } catch (const farfield::Error& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  }
}
