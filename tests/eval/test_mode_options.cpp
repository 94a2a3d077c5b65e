// The modes' one option parser (eval/mode_options.h): typed values within their ranges, errors naming the key and
// the value, and a key no mode read refused.
#include "farfield/eval/mode_options.h"

#include <gtest/gtest.h>

#include <tuple>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/eval/impostor_mode.h"
#include "farfield/eval/terrain_modes.h"

namespace farfield::eval {
namespace {

ModeContext withOptions(std::map<std::string, std::string> options) {
  ModeContext c;
  c.options = std::move(options);
  return c;
}

void expectErrorNaming(const std::function<void()>& fn, const std::string& key, const std::string& value) {
  try {
    fn();
    ADD_FAILURE() << key << "=" << value << " should be an error";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("--mode-option " + key), std::string::npos) << msg;
    EXPECT_NE(msg.find("'" + value + "'"), std::string::npos) << msg;
  }
}

TEST(ModeOptions, TypedValuesAndFallbacks) {
  const ModeContext c = withOptions({{"n", "2.5"}, {"k", "7"}, {"p", "0.25"}, {"c", "layer"}, {"s", "off"}, {"t", "1"}});
  EXPECT_EQ(numberOption(c, "n", 0.0, 0.0), 2.5);
  EXPECT_EQ(numberOption(c, "absent", 4.0, 0.0), 4.0);
  EXPECT_EQ(countOption(c, "k", 1), 7u);
  EXPECT_EQ(countOption(c, "absent", 3), 3u);
  EXPECT_EQ(positiveOption(c, "p", 1.0), 0.25);
  EXPECT_EQ(choiceOption(c, "c", "object", {"object", "layer"}), "layer");
  EXPECT_EQ(choiceOption(c, "absent", "object", {"object", "layer"}), "object");
  EXPECT_FALSE(switchOption(c, "s", true));
  EXPECT_TRUE(switchOption(c, "t", false));
  EXPECT_TRUE(switchOption(c, "absent", true));
}

TEST(ModeOptions, BadValuesNameTheKeyAndTheValue) {
  const ModeContext c = withOptions({{"n", "2.5x"}, {"low", "-1"}, {"high", "11"}, {"inf", "inf"}, {"k", "1.5"},
                                     {"zero", "0"}, {"c", "triangle"}, {"s", "maybe"}});
  expectErrorNaming([&] { numberOption(c, "n", 0.0, 0.0); }, "n", "2.5x");
  expectErrorNaming([&] { numberOption(c, "low", 0.0, 0.0); }, "low", "-1");
  expectErrorNaming([&] { numberOption(c, "high", 0.0, 0.0, 10.0); }, "high", "11");
  expectErrorNaming([&] { numberOption(c, "inf", 0.0, 0.0); }, "inf", "inf");
  expectErrorNaming([&] { countOption(c, "k", 1); }, "k", "1.5");
  expectErrorNaming([&] { countOption(c, "zero", 1); }, "zero", "0");
  expectErrorNaming([&] { positiveOption(c, "zero", 1.0); }, "zero", "0");
  expectErrorNaming([&] { choiceOption(c, "c", "object", {"object", "layer"}); }, "c", "triangle");
  expectErrorNaming([&] { switchOption(c, "s", true); }, "s", "maybe");
}

TEST(ModeOptions, WholeNumbersAndSizesWithinTheirTypes) {
  const ModeContext c = withOptions({{"k", "16384"}, {"mb", "2.5"}, {"wrap", "4294967808"}, {"huge", "1e300"},
                                     {"big", "99999999999999999999"}, {"neg", "-3"}});
  EXPECT_EQ(countOption(c, "k", 1, 0, 16384), 16384u);
  EXPECT_EQ(intOption(c, "k", 1, 0, 16384), 16384);
  EXPECT_EQ(intOption(c, "absent", 8, 1, 16), 8);
  EXPECT_EQ(mebibytesOption(c, "mb", 7), uint64_t(2.5 * 1048576.0));
  EXPECT_EQ(mebibytesOption(c, "absent", 7), 7u);
  expectErrorNaming([&] { countOption(c, "k", 1, 0, 16383); }, "k", "16384");
  // 2^32 + 512: an int conversion of the count wraps to 512.
  expectErrorNaming([&] { intOption(c, "wrap", 0, 0, 16384); }, "wrap", "4294967808");
  expectErrorNaming([&] { intOption(c, "big", 0, 0, 16384); }, "big", "99999999999999999999");
  expectErrorNaming([&] { intOption(c, "neg", 0, 0, 16384); }, "neg", "-3");
  // 1e300 MiB in bytes does not fit in 64 bits: converting it is undefined behaviour.
  expectErrorNaming([&] { mebibytesOption(c, "huge", 7); }, "huge", "1e300");
}

// The modes read their numbers through the parser above: a value beyond the runtime option's type is an error naming
// the key, never a conversion (undefined behaviour for a double beyond the integer's range, a wrapped value for a
// count beyond int). Constructing these modes reads no file.
TEST(ModeOptions, ModesRefuseNumbersBeyondTheirOptionTypes) {
  registerImpostorModes();
  for (const auto& [mode, key, value] : std::vector<std::tuple<std::string, std::string, std::string>>{
           {"mmi-dynamic", "gpu_budget_mb", "1e300"},
           {"mmi", "gpu_budget_mb", "1e30"},
           {"depth-mesh", "gpu_budget_mb", "1e300"},
           {"mmi-dynamic", "dynamic_resolution", "4294967808"},
           {"mmi-dynamic", "dynamic_resolution", "16385"},
           {"mmi-dynamic", "dynamic_grid_px", "4294967297"}}) {
    ModeContext c = withOptions({{"impostor_dir", "/nonexistent/store"}, {key, value}});
    expectErrorNaming([&] { createMode(mode, c); }, key, value);
  }
  ModeContext ok = withOptions({{"impostor_dir", "/nonexistent/store"}, {"gpu_budget_mb", "2.5"},
                                {"dynamic_resolution", "512"}, {"dynamic_grid_px", "4"}});
  EXPECT_NO_THROW(createMode("mmi-dynamic", ok));
}

TEST(ModeOptions, TerrainErrorsBeyondFloatAreErrors) {
  registerTerrainModes();
  for (const char* key : {"high_error", "low_error"}) {
    currentTerrainRun().reset();
    ModeContext c = withOptions({{"terrain", "fractal:33:1"}, {key, "1e300"}});
    try {
      createMode("high", c)->prepare(c);
      ADD_FAILURE() << key << "=1e300 should be an error";
    } catch (const Error& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(std::string("--mode-option ") + key), std::string::npos) << msg;
      EXPECT_NE(msg.find("out of range"), std::string::npos) << msg;
    }
  }
  currentTerrainRun().reset();
}

TEST(ModeOptions, AKeyNoModeReadIsAnError) {
  ModeContext c = withOptions({{"error_px", "2"}, {"erorr_px", "2"}});
  const ModeContext copy = c;  // modes receive copies: reads are shared
  numberOption(copy, "error_px", 0.0, 0.0);
  try {
    checkEveryOptionRead(c);
    ADD_FAILURE() << "erorr_px was read by no mode";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--mode-option erorr_px"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("error_px"), std::string::npos) << e.what();
  }
  c.option("erorr_px");
  EXPECT_NO_THROW(checkEveryOptionRead(c));
}

}  // namespace
}  // namespace farfield::eval
