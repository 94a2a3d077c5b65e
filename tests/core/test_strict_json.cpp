// Strict reading of saved options (core/strict_json.h): integers are whole numbers within their type, never converted
// out of range.
#include "farfield/core/strict_json.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>

namespace farfield {
namespace {

template <typename T>
std::string numberError(const std::string& text) {
  const nlohmann::json j = nlohmann::json::parse(R"({"k": )" + text + "}");
  StrictJson r(j, "options.json", "placement option");
  T out{};
  try {
    r.number("k", out);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(StrictJson, IntegersAtTheEdgesOfTheirTypes) {
  // double(INT64_MAX) and double(UINT64_MAX) are 2^63 and 2^64, one past the ranges: converting them is undefined.
  EXPECT_NE(numberError<int64_t>("9223372036854775808").find("must be an integer in range"), std::string::npos);
  EXPECT_NE(numberError<uint64_t>("18446744073709551616").find("must be an integer in range"), std::string::npos);
  EXPECT_NE(numberError<int>("2147483648").find("options.json"), std::string::npos);
  EXPECT_NE(numberError<int>("1e300").find("\"k\""), std::string::npos);
  EXPECT_NE(numberError<uint32_t>("-1").find("in range"), std::string::npos);
  EXPECT_NE(numberError<int>("2.5").find("in range"), std::string::npos);
  EXPECT_EQ(numberError<int64_t>("-9223372036854775808"), "");
  EXPECT_EQ(numberError<int>("2147483647"), "");
  EXPECT_EQ(numberError<uint64_t>("18446744073709549568"), "");  // the largest double below 2^64
}

TEST(StrictJson, FloatsBeyondFloatAreErrors) {
  EXPECT_NE(numberError<float>("1e300").find("out of range"), std::string::npos);
  EXPECT_EQ(numberError<float>("3.4e38"), "");
  EXPECT_EQ(numberError<double>("1e300"), "");
}

}  // namespace
}  // namespace farfield
