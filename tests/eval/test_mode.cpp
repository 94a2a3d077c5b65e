#include "farfield/eval/mode.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <memory>

#include <string>
#include <vector>

#include "farfield/core/error.h"

namespace farfield::eval {
namespace {

TEST(ModeRegistry, BuiltinsAreRegistered) {
  EXPECT_TRUE(hasMode("full"));
  EXPECT_TRUE(hasMode("culled"));
  const std::vector<std::string> names = modeNames();
  EXPECT_NE(std::find(names.begin(), names.end(), "full"), names.end());
  EXPECT_NE(std::find(names.begin(), names.end(), "culled"), names.end());
  EXPECT_FALSE(modeDescription("culled").empty());
  EXPECT_EQ(modeDescription("no-such-mode"), "");
}

TEST(ModeRegistry, UnknownModeThrowsErrorListingKnownOnes) {
  ModeContext context;
  try {
    createMode("frobnicate", context);
    FAIL() << "no error for an unknown mode";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("frobnicate"), std::string::npos) << what;
    EXPECT_NE(what.find("full"), std::string::npos) << what;
    EXPECT_NE(what.find("culled"), std::string::npos) << what;
  }
  const std::vector<std::string> names{"full", "nope"};
  EXPECT_THROW(checkModeNames(names), Error);
  const std::vector<std::string> good{"full", "culled"};
  EXPECT_NO_THROW(checkModeNames(good));
}

class CountingMode final : public Mode {
 public:
  explicit CountingMode(int tag) : tag_(tag) {}
  std::string name() const override { return "test-counting"; }
  void frame(FrameContext&) override {}
  std::map<std::string, double> info() const override { return {{"tag", double(tag_)}}; }

 private:
  int tag_;
};

TEST(ModeRegistry, RegisteredModeIsCreatedWithTheContext) {
  registerMode("test-counting", "a test mode", [](const ModeContext& c) {
    return std::make_unique<CountingMode>(std::stoi(c.option("tag", "-1")));
  });
  EXPECT_TRUE(hasMode("test-counting"));
  ModeContext context;
  context.options["tag"] = "42";
  auto mode = createMode("test-counting", context);
  EXPECT_EQ(mode->name(), "test-counting");
  EXPECT_EQ(mode->info().at("tag"), 42.0);
  ModeContext empty;
  EXPECT_EQ(createMode("test-counting", empty)->info().at("tag"), -1.0);
}

TEST(ModeContext, Options) {
  ModeContext context;
  context.options = parseModeOptions({"impostor_dir=baked/city", "budget_ms=16.6", "empty=", "a=b=c"});
  EXPECT_EQ(context.option("impostor_dir"), "baked/city");
  EXPECT_EQ(context.option("budget_ms"), "16.6");
  EXPECT_EQ(context.option("empty", "x"), "");
  EXPECT_EQ(context.option("a"), "b=c");
  EXPECT_EQ(context.option("missing", "fallback"), "fallback");
  EXPECT_EQ(context.requireOption("impostor_dir", "impostor"), "baked/city");
  try {
    context.requireOption("cells", "impostor");
    FAIL() << "no error for a missing option";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cells"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("impostor"), std::string::npos);
  }
  EXPECT_THROW(parseModeOptions({"novalue"}), Error);
  EXPECT_THROW(parseModeOptions({"=value"}), Error);
}

}  // namespace
}  // namespace farfield::eval
