#include "farfield/gpu/context.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "farfield/core/error.h"
#include "gpu/gpu_fixture.h"

namespace farfield::gpu {
namespace {

using test::GpuTest;

TEST_F(GpuTest, SharedContextIsOpenGL45Core) {
  const ContextInfo& info = sharedHeadlessContext().info();
  EXPECT_GE(info.major * 10 + info.minor, 45) << info.version;
  EXPECT_TRUE(info.core_profile);
  EXPECT_FALSE(info.renderer.empty());
  EXPECT_FALSE(info.vendor.empty());
  EXPECT_TRUE(info.platform == "egl-device" || info.platform == "egl-surfaceless") << info.platform;
  // GL_VERSION starts with "major.minor".
  EXPECT_EQ(info.version.rfind(std::to_string(info.major) + "." + std::to_string(info.minor), 0), 0u) << info.version;
  const std::string description = sharedHeadlessContext().description();
  EXPECT_NE(description.find(info.renderer), std::string::npos);
  EXPECT_NE(description.find(info.platform), std::string::npos);
}

TEST_F(GpuTest, SharedContextIsCreatedOnce) {
  EXPECT_EQ(&sharedHeadlessContext(), &sharedHeadlessContext());
}

// Sets an environment variable for the scope of a test.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old, had_ = true;
    ::setenv(name, value, 1);
  }
  ~ScopedEnv() {
    if (had_)
      ::setenv(name_, old_.c_str(), 1);
    else
      ::unsetenv(name_);
  }

 private:
  const char* name_;
  std::string old_;
  bool had_ = false;
};

TEST_F(GpuTest, UnknownPlatformInEnvironmentIsAnError) {
  ScopedEnv env("FF_GL_PLATFORM", "vulkan");
  try {
    Context::create();
    FAIL() << "expected farfield::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("FF_GL_PLATFORM"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("vulkan"), std::string::npos) << e.what();
  }
}

TEST_F(GpuTest, ExplicitPlatformsGiveAContextOrSayWhatWasTried) {
  // Mesa offers the surfaceless platform and a software EGL device; the NVIDIA driver offers devices only. Each
  // explicit request either works with 4.5 core or fails with an error naming the platform it tried.
  for (auto [platform, name] : {std::pair{Platform::Surfaceless, "egl-surfaceless"},
                                std::pair{Platform::Device, "egl-device"}}) {
    ContextOptions options;
    options.platform = platform;
    try {
      auto context = Context::create(options);
      EXPECT_EQ(context->info().platform, name);
      EXPECT_GE(context->info().major * 10 + context->info().minor, 45);
      EXPECT_TRUE(context->info().core_profile);
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
    sharedHeadlessContext();  // the new context was current; go back
  }
}

}  // namespace
}  // namespace farfield::gpu
