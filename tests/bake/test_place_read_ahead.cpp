// Reading placed impostors ahead: the impostors a walk will soon draw are loaded in an earlier frame's spare time
// (runtime::Walkthrough::loadAhead), so fewer frames load one themselves; and they are read and packed on a
// background thread (WalkthroughOptions::read_ahead), so that the frame that needs one only uploads it. Neither
// changes a frame.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "farfield/bake/place.h"
#include "farfield/gpu/render_target.h"
#include "farfield/runtime/walkthrough.h"
#include "farfield/scene/bvh.h"
#include "farfield/store/placement_store.h"
#include "support/small_placement.h"
#include "support/test_support.h"

namespace farfield::bake {
namespace {

// The small test city placed once for the suite's tests.
class PlaceReadAheadTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    city_ = std::make_unique<gen::City>(test::smallPlacementCity());
    dir_ = test::scratchDir("place_read_ahead").string();
    impostors_ = placeImpostors(gpu::sharedHeadlessContext(), city_->scene, test::handProfile(),
                                test::smallPlaceOptions(city_->scene), dir_)
                     .impostors;
  }
  static void TearDownTestSuite() { city_.reset(); }
  void SetUp() override {
    ASSERT_GT(impostors_, 0u);
    gpu::sharedHeadlessContext().makeCurrent();
    gpu_scene_ = std::make_unique<gpu::GpuScene>(city_->scene);
    bvh_ = std::make_unique<scene::Bvh>(city_->scene);
    renderer_ = std::make_unique<gpu::Renderer>();
  }
  // A walkthrough over the placement (read_ahead: its impostors read on a background thread).
  std::unique_ptr<runtime::Walkthrough> walkthrough(bool read_ahead) {
    runtime::WalkthroughOptions options = test::placedWalkthroughOptions(dir_);
    options.read_ahead = read_ahead;
    return std::make_unique<runtime::Walkthrough>(city_->scene, *gpu_scene_, *bvh_, *renderer_, options);
  }
  std::unique_ptr<gpu::GpuScene> gpu_scene_;
  std::unique_ptr<scene::Bvh> bvh_;
  std::unique_ptr<gpu::Renderer> renderer_;
  static std::unique_ptr<gen::City> city_;
  static std::string dir_;
  static size_t impostors_;
};
std::unique_ptr<gen::City> PlaceReadAheadTest::city_;
std::string PlaceReadAheadTest::dir_;
size_t PlaceReadAheadTest::impostors_ = 0;

TEST_F(PlaceReadAheadTest, ImpostorsLoadedAheadSpareTheFramesThatDrawThemAndChangeNoFrame) {
  // Every impostor read by the frame (or the read-ahead) that needs it.
  const auto plain_walkthrough = walkthrough(false), ahead_walkthrough = walkthrough(false);
  runtime::Walkthrough &plain = *plain_walkthrough, &ahead = *ahead_walkthrough;
  gpu::Renderer& renderer = *renderer_;
  const Box3 space = store::readPlacementIndex(dir_).view_space;
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
    EXPECT_EQ(ahead.loadAhead(camera, 0.0), 0.0);
    ahead.loadAhead(camera, 1000.0);
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

TEST_F(PlaceReadAheadTest, ImpostorsReadInTheBackgroundChangeNoFrame) {
  const auto plain_walkthrough = walkthrough(false), background_walkthrough = walkthrough(true);
  runtime::Walkthrough &plain = *plain_walkthrough, &background = *background_walkthrough;
  gpu::Renderer& renderer = *renderer_;
  const Box3 space = store::readPlacementIndex(dir_).view_space;
  gpu::RenderTarget plain_target(128, 128), background_target(128, 128);
  const int frames = 120;
  for (int f = 0; f < frames; ++f) {
    SCOPED_TRACE("frame " + std::to_string(f));
    const Camera camera = test::viewSpaceWalkCamera(space, f, frames);
    const runtime::FramePlan& a = plain.plan(camera);
    renderer.render(camera, a.items, plain_target);
    const runtime::FramePlan& b = background.plan(camera);
    EXPECT_EQ(b.items.size(), a.items.size());
    renderer.render(camera, b.items, background_target);
    EXPECT_EQ(background_target.readColor().pixels(), plain_target.readColor().pixels());
    EXPECT_EQ(background_target.readIds().pixels(), plain_target.readIds().pixels());
  }
  const auto stats = background.statistics();
  std::printf("%.0f impostors loaded: %.0f queued for the reader, %.0f read by it (%.0f taken ready, %.0f while "
              "read), %.0f read by the frame\n",
              stats.at("impostor_loads"), stats.at("impostors_queued_for_the_reader"),
              stats.at("impostors_read_in_the_background"), stats.at("impostors_taken_ready"),
              stats.at("impostors_taken_while_read"), stats.at("impostors_read_by_the_frame"));
  EXPECT_EQ(stats.at("impostor_loads"), plain.statistics().at("impostor_loads"));
  ASSERT_GT(stats.at("impostor_loads"), 0.0);
  // The walk's motion announces the problem views ahead: the reader read impostors the frames then took, and fewer
  // were read by the frame that drew them than were loaded.
  EXPECT_GT(stats.at("impostors_read_in_the_background"), 0.0);
  EXPECT_GT(stats.at("impostors_taken_ready") + stats.at("impostors_taken_while_read"), 0.0);
  EXPECT_LT(stats.at("impostors_read_by_the_frame"), stats.at("impostor_loads"));
  EXPECT_EQ(plain.statistics().count("impostors_read_by_the_frame"), 0u);
}

}  // namespace
}  // namespace farfield::bake
