// Reading placed impostors ahead (runtime::Walkthrough::readAheadPlaced): the impostors a walk will soon draw are
// loaded in an earlier frame's spare time, so fewer frames load one themselves, and no frame changes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "farfield/bake/place.h"
#include "farfield/gpu/render_target.h"
#include "farfield/runtime/walkthrough.h"
#include "farfield/scene/bvh.h"
#include "farfield/store/placement_store.h"
#include "support/small_placement.h"
#include "support/test_support.h"

namespace farfield::bake {
namespace {

TEST(PlaceReadAheadTest, ImpostorsLoadedAheadSpareTheFramesThatDrawThemAndChangeNoFrame) {
  const gen::City city = test::smallPlacementCity();
  const scene::Scene& scene = city.scene;
  const std::string dir = test::scratchDir("place_read_ahead").string();
  const PlaceReport report = placeImpostors(gpu::sharedHeadlessContext(), scene, test::handProfile(),
                                            test::smallPlaceOptions(scene), dir);
  ASSERT_GT(report.impostors, 0u);
  gpu::sharedHeadlessContext().makeCurrent();
  const gpu::GpuScene gpu_scene(scene);
  const scene::Bvh bvh(scene);
  gpu::Renderer renderer;
  runtime::WalkthroughOptions options = test::placedWalkthroughOptions(dir);
  runtime::Walkthrough plain(scene, gpu_scene, bvh, renderer, options);
  runtime::Walkthrough ahead(scene, gpu_scene, bvh, renderer, options);
  const Box3 space = store::readPlacementIndex(dir).view_space;
  gpu::RenderTarget plain_target(128, 128), ahead_target(128, 128);
  size_t plain_loads = 0, ahead_loads = 0, impostor_frames = 0;
  const int frames = 120;
  for (int f = 0; f < frames; ++f) {
    SCOPED_TRACE("frame " + std::to_string(f));
    const Camera camera = test::viewSpaceWalkCamera(space, f, frames);
    const runtime::FramePlan& a = plain.plan(camera);
    plain_loads += a.report.loaded;
    renderer.render(camera, a.items, plain_target);
    const runtime::FramePlan& b = ahead.plan(camera);
    ahead_loads += b.report.loaded;
    impostor_frames += b.items.size() > b.geometry_items;
    renderer.render(camera, b.items, ahead_target);
    EXPECT_EQ(ahead_target.readColor().pixels(), plain_target.readColor().pixels());
    EXPECT_EQ(ahead_target.readIds().pixels(), plain_target.readIds().pixels());
    // No budget, no work; then a generous one.
    EXPECT_EQ(ahead.readAheadPlaced(camera, 0.0), 0.0);
    ahead.readAheadPlaced(camera, 1000.0);
  }
  const auto stats = ahead.statistics();
  std::printf("%zu frames with impostors; frames that loaded one: %zu without reading ahead, %zu with (%.0f read "
              "ahead)\n", impostor_frames, plain_loads, ahead_loads, stats.at("impostors_read_ahead"));
  ASSERT_GT(plain_loads, 0u);  // the walk needs impostors: there is something to read ahead
  EXPECT_GT(stats.at("impostors_read_ahead"), 0.0);
  EXPECT_LT(ahead_loads, plain_loads);
  // Every impostor is loaded once either way (nothing evicted under the default budget).
  EXPECT_EQ(stats.at("cache_evictions"), 0.0);
  EXPECT_LE(plain.statistics().at("impostor_loads"), stats.at("impostor_loads"));
}

}  // namespace
}  // namespace farfield::bake
