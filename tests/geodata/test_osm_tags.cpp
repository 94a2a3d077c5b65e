// OSM tag values: lengths with units, level counts and the height rules, against hand-computed values.
#include <gtest/gtest.h>

#include <map>
#include <string>

#include "farfield/geodata/osm_tags.h"

using farfield::geodata::buildingHeight;
using farfield::geodata::HeightOptions;
using farfield::geodata::HeightSource;
using farfield::geodata::parseLength;
using farfield::geodata::parseLevels;

namespace {

farfield::geodata::BuildingHeight heightOf(const std::map<std::string, std::string>& tags,
                                           const HeightOptions& options = {}) {
  return buildingHeight(
      [&](const char* key) -> const char* {
        auto it = tags.find(key);
        return it == tags.end() ? nullptr : it->second.c_str();
      },
      options);
}

}  // namespace

TEST(OsmTags, LengthsWithUnits) {
  EXPECT_DOUBLE_EQ(*parseLength("12"), 12.0);
  EXPECT_DOUBLE_EQ(*parseLength(" 12.5 "), 12.5);
  EXPECT_DOUBLE_EQ(*parseLength("12,5"), 12.5);
  EXPECT_DOUBLE_EQ(*parseLength("12 m"), 12.0);
  EXPECT_DOUBLE_EQ(*parseLength("12m"), 12.0);
  EXPECT_DOUBLE_EQ(*parseLength("12 metres"), 12.0);
  EXPECT_DOUBLE_EQ(*parseLength("0.5 km"), 500.0);
  EXPECT_DOUBLE_EQ(*parseLength("250 cm"), 2.5);
  EXPECT_NEAR(*parseLength("40 ft"), 40 * 0.3048, 1e-12);
  EXPECT_NEAR(*parseLength("40'"), 40 * 0.3048, 1e-12);
  EXPECT_NEAR(*parseLength("12'6\""), 12 * 0.3048 + 6 * 0.0254, 1e-12);
  EXPECT_NEAR(*parseLength("12 ft 6 in"), 12 * 0.3048 + 6 * 0.0254, 1e-12);
  for (const char* bad : {"", "tall", "-5", "12 parsecs", "1e400", "3000", "12 m high", "m", ".", "1..2"})
    EXPECT_FALSE(parseLength(bad).has_value()) << bad;
}

TEST(OsmTags, Levels) {
  EXPECT_DOUBLE_EQ(*parseLevels("3"), 3.0);
  EXPECT_DOUBLE_EQ(*parseLevels("2.5"), 2.5);
  EXPECT_DOUBLE_EQ(*parseLevels("3;5"), 5.0);
  for (const char* bad : {"", "three", "-1", "3 floors", "1000"}) EXPECT_FALSE(parseLevels(bad).has_value()) << bad;
}

TEST(OsmTags, HeightRules) {
  // height wins over levels.
  auto h = heightOf({{"height", "12 m"}, {"building:levels", "10"}});
  EXPECT_EQ(h.source, HeightSource::Height);
  EXPECT_DOUBLE_EQ(h.top, 12.0);
  EXPECT_DOUBLE_EQ(h.base, 0.0);
  // levels x 3 m plus roof levels.
  h = heightOf({{"building:levels", "5"}, {"roof:levels", "1"}});
  EXPECT_EQ(h.source, HeightSource::Levels);
  EXPECT_DOUBLE_EQ(h.top, 18.0);
  // Nothing tagged: the default.
  HeightOptions options;
  options.default_height = 7.5f;
  h = heightOf({{"building", "yes"}}, options);
  EXPECT_EQ(h.source, HeightSource::Default);
  EXPECT_DOUBLE_EQ(h.top, 7.5);
  EXPECT_FALSE(h.bad_value);
  // min_height and building:min_level.
  h = heightOf({{"min_height", "10"}, {"height", "20"}});
  EXPECT_DOUBLE_EQ(h.base, 10.0);
  EXPECT_DOUBLE_EQ(h.top, 20.0);
  h = heightOf({{"building:min_level", "2"}, {"building:levels", "4"}});
  EXPECT_DOUBLE_EQ(h.base, 6.0);
  EXPECT_DOUBLE_EQ(h.top, 12.0);
  // An unreadable height falls back to the levels and is flagged.
  h = heightOf({{"height", "very"}, {"building:levels", "2"}});
  EXPECT_EQ(h.source, HeightSource::Levels);
  EXPECT_DOUBLE_EQ(h.top, 6.0);
  EXPECT_TRUE(h.bad_value);
  // A top at or below the base becomes one level above it.
  h = heightOf({{"min_height", "15"}, {"height", "10"}});
  EXPECT_DOUBLE_EQ(h.base, 15.0);
  EXPECT_DOUBLE_EQ(h.top, 18.0);
  EXPECT_TRUE(h.bad_value);
}

TEST(OsmTags, HighwayClasses) {
  const auto* primary = farfield::geodata::findHighwayClass("primary");
  ASSERT_NE(primary, nullptr);
  EXPECT_EQ(primary->street_class, 0);
  const auto* footway = farfield::geodata::findHighwayClass("footway");
  ASSERT_NE(footway, nullptr);
  EXPECT_LT(footway->width, primary->width);
  EXPECT_EQ(farfield::geodata::findHighwayClass("rocket_lane"), nullptr);
  for (const std::string& name : farfield::geodata::defaultHighwaySelection())
    EXPECT_NE(farfield::geodata::findHighwayClass(name), nullptr) << name;
}
