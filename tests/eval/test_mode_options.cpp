// The modes' one option parser (eval/mode_options.h): typed values within their ranges, errors naming the key and
// the value, and a key no mode read refused.
#include "farfield/eval/mode_options.h"

#include <gtest/gtest.h>

#include "farfield/core/error.h"

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
