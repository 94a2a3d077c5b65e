// The PVS sampler's occlusion culling is exact: from street viewpoints of a generated city it sees the ids of
// drawing every object whole into the six faces (the brute force), and it leaves most of the city's triangles out.
#include <gtest/gtest.h>

#include <set>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/eval/pvs_speed.h"
#include "farfield/gen/city.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/renderer.h"
#include "farfield/urban/pvs.h"

namespace farfield::eval {
namespace {

struct StreetCity {
  gen::CityOptions options;
  gen::City city;
  std::vector<Vec3> eyes;  // the middle of every third street and every fifth junction, 1.7 m above the ground
  StreetCity() {
    options.blocks = 24;
    options.detail = 1;
    options.seed = 23;
    options.objects = gen::ObjectGrouping::Buildings;
    city = gen::generateCity(options);
    auto eye = [&](Vec2 p) { return Vec3(p, gen::cityGroundHeight(options, city.bounds, p) + 1.7f); };
    for (uint32_t s = 0; s < city.streets.streetCount(); s += 3)
      eyes.push_back(eye(0.5f * (city.streets.originPosition(2 * s) + city.streets.destinationPosition(2 * s))));
    for (uint32_t j = 0; j < city.streets.junctionCount(); j += 5) eyes.push_back(eye(city.streets.position(j)));
  }
};

const StreetCity& streetCity() {
  static const StreetCity* city = new StreetCity;
  return *city;
}

std::set<uint32_t> idsOf(const std::vector<uint8_t>& seen) {
  std::set<uint32_t> ids;
  for (size_t id = 1; id < seen.size(); ++id)
    if (seen[id]) ids.insert(uint32_t(id));
  return ids;
}

TEST(PvsOcclusion, SeesWhatDrawingEveryObjectSees) {
  gpu::sharedHeadlessContext();
  const StreetCity& c = streetCity();
  ASSERT_GE(c.eyes.size(), 10u);
  const gpu::GpuScene gpu_scene(c.city.scene);
  const std::vector<gpu::DrawItem> everything = gpu_scene.drawItems();
  urban::PvsOptions options;
  options.face_size = 64;
  gpu::Renderer renderer;
  gpu::RenderTarget target(options.face_size, options.face_size);
  std::vector<std::unique_ptr<urban::PvsSampler>> samplers;
  for (double share : {0.0, 0.1, 1.0}) {
    options.occluder_share = share;
    samplers.push_back(std::make_unique<urban::PvsSampler>(gpu_scene, options));
  }
  uint64_t hidden = 0, drawn = 0, unculled = 0;
  for (size_t e = 0; e < c.eyes.size(); ++e) {
    std::set<uint32_t> expected;
    for (const Camera& camera :
         urban::cubeFaceCameras(c.eyes[e], options.face_size, options.near_plane, options.far_plane)) {
      renderer.render(camera, everything, target, gpu::RenderMode::ItemBuffer);
      const image::IdImage ids = target.readIds();
      for (uint32_t id : ids.pixels())
        if (id) expected.insert(id);
    }
    ASSERT_FALSE(expected.empty());
    std::vector<gpu::DrawItem> in_frusta;
    for (const Camera& camera :
         urban::cubeFaceCameras(c.eyes[e], options.face_size, options.near_plane, options.far_plane))
      gpu_scene.appendDrawItems({}, in_frusta, camera);
    for (const gpu::DrawItem& item : in_frusta) unculled += item.triangleCount();
    for (size_t s = 0; s < samplers.size(); ++s) {
      std::vector<uint8_t> seen;
      const urban::ViewpointStats stats = samplers[s]->sampleViewpoint(c.eyes[e], seen);
      EXPECT_EQ(idsOf(seen), expected) << "eye " << e << ", sampler " << s;
      if (s == 1) {
        hidden += stats.objects_hidden;
        drawn += stats.triangles_drawn;
      }
    }
  }
  // At street level the first row of buildings hides most of the city: most objects in the frusta, and most of
  // the triangles.
  EXPECT_GT(hidden, 10 * c.eyes.size());
  EXPECT_LT(2 * drawn, unculled);
}

TEST(PvsSpeed, ReportsTheRunsAgainstTheUnculledReference) {
  gpu::sharedHeadlessContext();
  const StreetCity& c = streetCity();
  const gpu::GpuScene gpu_scene(c.city.scene);
  PvsSpeedOptions options;
  options.pvs.face_size = 32;
  options.occluder_shares = {0.05, 0.2};
  const std::vector<Vec3> eyes(c.eyes.begin(), c.eyes.begin() + 6);
  const PvsSpeedReport report = measurePvsSpeed(gpu_scene, eyes, options);
  ASSERT_EQ(report.runs.size(), 3u);
  EXPECT_EQ(report.points, 6u);
  EXPECT_FALSE(report.runs[0].occlusion);
  EXPECT_EQ(report.runs[0].objects_hidden, 0u);
  for (size_t r = 1; r < 3; ++r) {
    EXPECT_TRUE(report.runs[r].occlusion);
    EXPECT_EQ(report.runs[r].mismatched_points, 0u);
    EXPECT_LT(report.runs[r].triangles_drawn, report.runs[0].triangles_drawn);
    EXPECT_GT(report.runs[r].objects_hidden, 0u);
  }
  EXPECT_DOUBLE_EQ(report.runs[1].occluder_share, 0.05);
  EXPECT_THROW(measurePvsSpeed(gpu_scene, {}, options), Error);
}

}  // namespace
}  // namespace farfield::eval
