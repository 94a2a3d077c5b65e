#include "farfield/core/checked_cast.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

namespace farfield {
namespace {

std::string errorOf(auto&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(CheckedCast, FloatingToIntegerAtTheEdgesOfTheRange) {
  // Every value the cast truncates into range is accepted; the first one past either end is not.
  EXPECT_TRUE(fitsIn<int32_t>(2147483647.0));
  EXPECT_TRUE(fitsIn<int32_t>(2147483647.9));
  EXPECT_FALSE(fitsIn<int32_t>(2147483648.0));
  EXPECT_TRUE(fitsIn<int32_t>(-2147483648.0));
  EXPECT_TRUE(fitsIn<int32_t>(-2147483648.9));
  EXPECT_FALSE(fitsIn<int32_t>(-2147483649.0));
  EXPECT_TRUE(fitsIn<uint32_t>(-0.9));
  EXPECT_FALSE(fitsIn<uint32_t>(-1.0));
  EXPECT_TRUE(fitsIn<uint32_t>(4294967295.0));
  EXPECT_FALSE(fitsIn<uint32_t>(4294967296.0));
  // double(INT64_MAX) is 2^63, one past the end: a naive "d <= double(max)" test accepts it.
  EXPECT_FALSE(fitsIn<int64_t>(double(std::numeric_limits<int64_t>::max())));
  EXPECT_TRUE(fitsIn<int64_t>(std::nextafter(9223372036854775808.0, 0.0)));
  EXPECT_TRUE(fitsIn<int64_t>(-9223372036854775808.0));
  EXPECT_FALSE(fitsIn<int64_t>(std::nextafter(-9223372036854775808.0, -1e300)));
  EXPECT_FALSE(fitsIn<uint64_t>(18446744073709551616.0));
  EXPECT_TRUE(fitsIn<uint64_t>(std::nextafter(18446744073709551616.0, 0.0)));
  EXPECT_TRUE(fitsIn<uint8_t>(255.5f));
  EXPECT_FALSE(fitsIn<uint8_t>(256.0f));
  for (double bad : {std::nan(""), std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                     1e300, -1e300}) {
    EXPECT_FALSE(fitsIn<int>(bad)) << bad;
    EXPECT_FALSE(fitsIn<size_t>(bad)) << bad;
    EXPECT_FALSE(fitsIn<int64_t>(bad)) << bad;
  }
}

TEST(CheckedCast, IntegerNarrowingAndSignChanges) {
  EXPECT_TRUE(fitsIn<int>(uint64_t(2147483647)));
  EXPECT_FALSE(fitsIn<int>(uint64_t(2147483648)));
  EXPECT_FALSE(fitsIn<int>((uint64_t(1) << 32) + 512));  // would wrap to 512
  EXPECT_FALSE(fitsIn<uint32_t>(int64_t(-1)));
  EXPECT_FALSE(fitsIn<size_t>(-1));
  EXPECT_TRUE(fitsIn<uint64_t>(std::numeric_limits<int64_t>::max()));
  EXPECT_FALSE(fitsIn<int64_t>(std::numeric_limits<uint64_t>::max()));
}

TEST(CheckedCast, DoubleToFloat) {
  EXPECT_TRUE(fitsIn<float>(double(std::numeric_limits<float>::max())));
  EXPECT_FALSE(fitsIn<float>(1e39));
  EXPECT_FALSE(fitsIn<float>(-1e300));
  EXPECT_TRUE(fitsIn<float>(1e-300));  // underflows to 0: defined
  EXPECT_TRUE(fitsIn<float>(std::numeric_limits<double>::infinity()));
  EXPECT_TRUE(fitsIn<double>(1e38f));
  EXPECT_TRUE(fitsIn<float>(std::numeric_limits<uint64_t>::max()));
}

TEST(CheckedCast, ErrorsNameTheInputAndTheRange) {
  EXPECT_EQ(checkedCast<int>(12.7, "f", "x"), 12);
  EXPECT_EQ(checkedCast<uint32_t>(uint64_t(7), "f", "x"), 7u);
  EXPECT_EQ(errorOf([] { checkedCast<int>(1e300, "city.json", "vertex 3"); }),
            "city.json: vertex 3: 1.0000000000000001e+300 is out of range (expected an integer in "
            "-2147483648..2147483647)");
  EXPECT_EQ(errorOf([] { checkedCast<uint8_t>(-1, "--opt", "value"); }),
            "--opt: value: -1 is out of range (expected an integer in 0..255)");
  EXPECT_NE(errorOf([] { checkedCast<float>(1e300, "p.json", "fov"); }).find("p.json: fov: "), std::string::npos);
}

TEST(CheckedCast, WholeNumbersKeepEveryDigit) {
  EXPECT_EQ(wholeNumber<int64_t>(-3.0, "f", "x"), -3);
  EXPECT_EQ(errorOf([] { wholeNumber<int>(2.5, "f", "count"); }), "f: count: 2.5 is not a whole number");
  EXPECT_NE(errorOf([] { wholeNumber<int>(std::nan(""), "f", "count"); }).find("out of range"), std::string::npos);
  EXPECT_EQ(wholeNumber<size_t>(uint32_t(9), "f", "x"), 9u);
}

TEST(CheckedCast, CapSize) {
  EXPECT_EQ(capSize<uint64_t>(100, 100, "dem.tif", "raster size"), 100u);
  EXPECT_EQ(errorOf([] { capSize<uint64_t>(101, 100, "dem.tif", "raster of"); }),
            "dem.tif: raster of 101 exceeds the limit of 100");
}

}  // namespace
}  // namespace farfield
