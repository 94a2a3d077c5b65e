#include "farfield/core/number_format.h"

#include <gtest/gtest.h>

#include <string>

namespace farfield {
namespace {

TEST(NumberFormat, CountsTakeACommaEveryThreeDigits) {
  EXPECT_EQ(thousands(0), "0");
  EXPECT_EQ(thousands(999), "999");
  EXPECT_EQ(thousands(1000), "1,000");
  EXPECT_EQ(thousands(865909), "865,909");
  EXPECT_EQ(thousands(1234567), "1,234,567");
  EXPECT_EQ(thousands(18446744073709551615ull), "18,446,744,073,709,551,615");
  // Against removing the commas again: every count from 0 to 100,000 in steps that cross each group boundary.
  for (uint64_t v = 0; v <= 100000; v += 997) {
    std::string digits = thousands(v);
    std::erase(digits, ',');
    EXPECT_EQ(digits, std::to_string(v));
  }
}

TEST(NumberFormat, OneConversionWithItsTextAndALongResultCut) {
  EXPECT_EQ(formatNumber("%.2f", 3.14159), "3.14");
  EXPECT_EQ(formatNumber("%.1f ms", 12.25), "12.2 ms");
  EXPECT_EQ(formatNumber("%.2fx", 1.0), "1.00x");
  EXPECT_EQ(formatNumber("%.0f", 1e70).size(), 63u);
}

}  // namespace
}  // namespace farfield
