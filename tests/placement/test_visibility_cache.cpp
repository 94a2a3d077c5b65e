// The visibility cache (placement/visibility_cache.h): an eye's region found by repeating the view space's partition
// is the region the view space itself gives it (brute force: every region a problem, so every leaf is visited and
// holds CPVs); the file reads back whole; bad files are errors naming the file.
#include "farfield/placement/visibility_cache.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <random>

#include "farfield/core/error.h"
#include "farfield/placement/view_space.h"
#include "support/test_support.h"

namespace farfield::placement {
namespace {

TEST(VisibilityCache, AnEyesRegionIsTheViewSpacesAndReadsBack) {
  std::mt19937 rng(21);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int trial = 0; trial < 4; ++trial) {
    ViewSpaceOptions o;
    const Vec3 lo(-137.3f * u(rng), -91.7f * u(rng), 1.2f);
    o.box = Box3::fromPoints(lo, lo + Vec3(60.0f + 200.0f * u(rng), 60.0f + 150.0f * u(rng), 0.5f));
    o.min_region_size = 17.0f + 20.0f * u(rng);
    o.t_max = 1.0;
    VisibilityCache cache;
    cache.key = visibilityCacheKey(99, o.box, o.min_region_size, 32, 1000.0f, 4);
    EXPECT_EQ(cache.key.at("visibility_grid"), 4);
    EXPECT_FALSE(visibilityCacheKey(99, o.box, o.min_region_size, 32, 1000.0f, 2).contains("visibility_grid"));
    uint32_t next = 1;
    ViewSpaceCallbacks cb;
    cb.visible_set = [&](const Box3& region) {
      const Vec3 e = region.extent();
      if (std::max({e.x, e.y, e.z}) <= o.min_region_size)
        cache.regions[{region.lo.x, region.lo.y, region.lo.z}] = {next++};
      return std::vector<uint32_t>{};
    };
    cb.estimate = [](const Box3&, const Vdi&, const std::vector<uint32_t>*) { return 2.0; };  // every view a problem
    const ViewSpace vs = approximateProblemViewSpace(o, cb);
    ASSERT_GT(cache.regions.size(), 8u);

    const std::string file = (test::scratchDir("visibility_cache") / "cache.json").string();
    std::ofstream(file) << cache.toJson().dump();
    const VisibilityCache read = readVisibilityCache(file);
    EXPECT_EQ(read.key, cache.key);
    EXPECT_EQ(read.regions, cache.regions);
    EXPECT_EQ(read.minRegionSize(), o.min_region_size);
    for (int k = 0; k < 400; ++k) {
      // Some eyes on the partition's planes: a corner of a leaf.
      Vec3 eye = o.box.lo + o.box.extent() * Vec3(u(rng), u(rng), u(rng));
      if (k % 5 == 0) eye = vs.cpvs[size_t(k) % vs.cpvs.size()].region.lo;
      const std::optional<uint32_t> cpv = vs.lookup(eye, Vec3(1.0f, 0.0f, 0.0f));
      ASSERT_TRUE(cpv.has_value());
      const Box3 expected = vs.cpvs[*cpv].region;
      const std::optional<Box3> region = read.regionOf(eye);
      ASSERT_TRUE(region.has_value());
      EXPECT_EQ(region->lo, expected.lo) << "trial " << trial << " eye " << k;
      EXPECT_EQ(region->hi, expected.hi);
      const std::vector<uint32_t>* visible = read.visibleFrom(eye);
      ASSERT_NE(visible, nullptr);
      EXPECT_EQ(*visible, cache.regions.at({expected.lo.x, expected.lo.y, expected.lo.z}));
    }
    EXPECT_FALSE(read.regionOf(o.box.hi + Vec3(1.0f)).has_value());
    EXPECT_EQ(read.visibleFrom(o.box.lo - Vec3(1.0f)), nullptr);
  }
}

TEST(VisibilityCache, BadFilesAreErrorsNamingThem) {
  const std::string dir = test::scratchDir("visibility_cache_bad").string();
  const auto expectError = [](const std::string& path) {
    try {
      readVisibilityCache(path);
      ADD_FAILURE() << "expected an error for " << path;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  };
  expectError(dir + "/missing.json");
  std::ofstream(dir + "/garbage.json") << "{not json";
  expectError(dir + "/garbage.json");
  std::ofstream(dir + "/no_regions.json") << R"({"key": {}})";
  expectError(dir + "/no_regions.json");
  std::ofstream(dir + "/bad_lo.json") << R"({"key": {}, "regions": [{"lo": [1, 2], "visible": [3]}]})";
  expectError(dir + "/bad_lo.json");
  VisibilityCache keyless;
  EXPECT_THROW(keyless.viewSpace(), Error);
  EXPECT_THROW(keyless.minRegionSize(), Error);
}

}  // namespace
}  // namespace farfield::placement
