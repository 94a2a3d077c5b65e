#include "farfield/gpu/occlusion_culler.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>
#include <vector>

#include "farfield/gpu/render_target.h"
#include "farfield/scene/builtin.h"
#include "gpu/gpu_fixture.h"
#include "gpu/street_scene.h"

namespace farfield::gpu {
namespace {

using test::GpuTest;

float bruteFarthest(const std::vector<float>& depth, int width, int height, int x0, int y0, int x1, int y1) {
  float result = 1.0f;
  bool any = false;
  for (int y = std::max(y0, 0); y <= std::min(y1, height - 1); ++y)
    for (int x = std::max(x0, 0); x <= std::min(x1, width - 1); ++x) {
      result = any ? std::min(result, depth[size_t(y) * size_t(width) + size_t(x)]) : depth[size_t(y) * width + x];
      any = true;
    }
  return result;
}

TEST(DepthPyramid, FarthestIsNeverNearerThanAPixelOfTheRectangleAndComesFromNearby) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (const auto& [width, height] : {std::pair{1, 1}, {7, 5}, {64, 36}, {97, 61}}) {
    // Smooth depth with a few deep holes, so that rectangles of every size meet both.
    std::vector<float> depth(size_t(width) * size_t(height));
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x)
        depth[size_t(y) * width + x] = u(rng) < 0.02f ? 0.0f : 0.3f + 0.2f * std::sin(0.3f * x) * std::cos(0.2f * y);
    DepthPyramid pyramid;
    pyramid.build(depth, width, height);
    std::uniform_int_distribution<int> px(-3, width + 2), py(-3, height + 2);
    int exact = 0;
    for (int trial = 0; trial < 2000; ++trial) {
      int x0 = px(rng), x1 = px(rng), y0 = py(rng), y1 = py(rng);
      if (x0 > x1) std::swap(x0, x1);
      if (y0 > y1) std::swap(y0, y1);
      const float got = pyramid.farthest(x0, y0, x1, y1);
      const float want = bruteFarthest(depth, width, height, x0, y0, x1, y1);
      ASSERT_LE(got, want) << width << "x" << height << " [" << x0 << "," << x1 << "]x[" << y0 << "," << y1 << "]";
      // The coarser level it reads covers at most four times the rectangle's extent around it.
      const int ex = 4 * (x1 - x0 + 1), ey = 4 * (y1 - y0 + 1);
      ASSERT_GE(got, bruteFarthest(depth, width, height, x0 - ex, y0 - ey, x1 + ex, y1 + ey));
      exact += got == want;
    }
    EXPECT_GT(exact, 200) << "the pyramid should often be exact, not only conservative";
  }
}

// The occluders are the nearest boxes until they hold the share of all triangles, those that follow outside the
// boxes (also_triangles) included, and every box reaching the eye: against a brute-force count over random sets.
TEST(SplitNearestFirst, OccludersHoldTheirShareOfTheTrianglesThatFollowToo) {
  std::mt19937 rng(12);
  std::uniform_real_distribution<float> depth(0.0f, 1.0f);
  std::uniform_int_distribution<int> tris(1, 500);
  size_t grew = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const size_t n = 1 + size_t(trial % 40);
    std::vector<ScreenBox> boxes(n);
    std::vector<uint64_t> triangles(n);
    for (size_t i = 0; i < n; ++i) {
      boxes[i].reaches_eye = trial % 5 == 0 && i == n / 2;  // as projectBox gives it: infinitely near
      boxes[i].nearest = boxes[i].reaches_eye ? std::numeric_limits<float>::infinity() : depth(rng);
      triangles[i] = uint64_t(tris(rng));
    }
    const double share = 0.05 * double(trial % 20);
    const uint64_t also = trial % 2 ? uint64_t(tris(rng)) * 40 : 0;
    std::vector<uint32_t> order(n);
    for (size_t i = 0; i < n; ++i) order[i] = uint32_t(i);
    const size_t split = splitNearestFirst(
        order, boxes, [&](uint32_t i) { return triangles[i]; }, share, also);
    // Brute force: sort nearest first (eye-reaching boxes first), take until the share is held.
    std::vector<uint32_t> expected(n);
    for (size_t i = 0; i < n; ++i) expected[i] = uint32_t(i);
    std::sort(expected.begin(), expected.end(), [&](uint32_t a, uint32_t b) {
      return boxes[a].nearest != boxes[b].nearest ? boxes[a].nearest > boxes[b].nearest : a < b;
    });
    ASSERT_EQ(order, expected);
    uint64_t total = also, held = 0;
    for (const uint64_t t : triangles) total += t;
    size_t want = 0;
    while (want < n && double(held) < share * double(total)) held += triangles[expected[want++]];
    for (size_t k = 0; k < n; ++k)
      if (boxes[expected[k]].reaches_eye) want = std::max(want, k + 1);
    EXPECT_EQ(split, want) << "trial " << trial;
    if (also > 0) {
      std::vector<uint32_t> again(n);
      for (size_t i = 0; i < n; ++i) again[i] = uint32_t(i);
      grew += split > splitNearestFirst(again, boxes, [&](uint32_t i) { return triangles[i]; }, share, 0);
    }
  }
  EXPECT_GT(grew, 10u);  // the triangles that follow ask for more occluders
}

TEST(ProjectBox, FootprintHoldsEveryPointOfTheBoxAndNearestIsItsNearestDepth) {
  std::mt19937 rng(8);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  int reaching = 0, projected = 0;
  for (int trial = 0; trial < 300; ++trial) {
    Camera camera;
    camera.width = 80 + trial % 50;
    camera.height = 40 + trial % 30;
    camera.near_plane = 0.3f;
    camera.eye = Vec3(20.0f * u(rng), 20.0f * u(rng), 2.0f + 5.0f * u(rng));
    camera.at = camera.eye + Vec3(u(rng), u(rng), 0.3f * u(rng));
    const Mat4 model = glm::rotate(glm::translate(Mat4(1.0f), Vec3(5.0f * u(rng), 5.0f * u(rng), 0.0f)), u(rng),
                                   Vec3(0.0f, 0.0f, 1.0f));
    Box3 box;
    box.expand(Vec3(4.0f * u(rng), 4.0f * u(rng), 3.0f * u(rng)));
    box.expand(Vec3(4.0f * u(rng), 4.0f * u(rng), 3.0f * u(rng)));
    const ScreenBox s = projectBox(box, camera.viewProjection() * model, camera.width, camera.height);
    if (s.reaches_eye) {
      ++reaching;
      EXPECT_EQ(s.x0, 0);
      EXPECT_EQ(s.x1, camera.width - 1);
      continue;
    }
    ++projected;
    float nearest_seen = -1.0f;
    for (int k = 0; k < 400; ++k) {
      const Vec3 t((u(rng) + 1.0f) * 0.5f, (u(rng) + 1.0f) * 0.5f, (u(rng) + 1.0f) * 0.5f);
      const Vec3 local = box.lo + t * (box.hi - box.lo);
      float w = 0.0f;
      const Vec3 p = camera.project(Vec3(model * Vec4(local, 1.0f)), &w);
      ASSERT_GT(w, 0.0f);
      ASSERT_LE(p.z, s.nearest * (1.0f + 1e-5f)) << "trial " << trial;
      nearest_seen = std::max(nearest_seen, p.z);
      // Camera::project has row 0 at the top; the footprint has GL rows (row 0 at the bottom).
      const int x = int(std::floor(p.x)), y = camera.height - 1 - int(std::floor(p.y));
      if (x < 0 || y < 0 || x >= camera.width || y >= camera.height) continue;
      ASSERT_TRUE(x >= s.x0 && x <= s.x1 && y >= s.y0 && y <= s.y1)
          << "trial " << trial << " pixel " << x << "," << y << " outside [" << s.x0 << "," << s.x1 << "]x[" << s.y0
          << "," << s.y1 << "]";
    }
    // Interior samples come close to the nearest corner but not beyond it.
    EXPECT_GE(nearest_seen, 0.5f * s.nearest) << "trial " << trial;
  }
  EXPECT_GT(reaching, 5);
  EXPECT_GT(projected, 100);
}

// The street canyon of street_scene.h, culled per cluster of 12 triangles.
class OcclusionStreetTest : public GpuTest {
 protected:
  void SetUp() override {
    GpuTest::SetUp();
    scene_ = test::streetCanyonScene();
    GpuSceneOptions options;
    options.cluster_triangles = 12;
    gpu_scene_ = std::make_unique<GpuScene>(scene_, options);
  }

  static Camera streetCamera(std::mt19937& rng, bool above) { return test::streetCanyonCamera(rng, above); }

  scene::Scene scene_;
  std::unique_ptr<GpuScene> gpu_scene_;
};

TEST_F(OcclusionStreetTest, FramesAreIdenticalToFrustumCulledFramesAndHiddenItemsAreDropped) {
  Renderer renderer;
  RenderTarget target(96, 64);
  std::mt19937 rng(4);
  uint64_t hidden = 0, hidden_triangles = 0, offered_triangles = 0;
  for (int trial = 0; trial < 40; ++trial) {
    // In the street at eye height, some frames higher up (above the walls: little is hidden there).
    const Camera camera = streetCamera(rng, trial % 4 == 3);
    std::vector<DrawItem> items;
    std::vector<Box3> bounds;
    gpu_scene_->appendDrawItems({}, items, camera, &bounds);
    ASSERT_EQ(items.size(), bounds.size());
    for (const DrawItem& item : items) offered_triangles += item.triangleCount();
    for (RenderMode mode : {RenderMode::Shaded, RenderMode::ItemBuffer}) {
      renderer.render(camera, items, target, mode);
      const image::ColorImage want_color = target.readColor();
      const image::IdImage want_ids = target.readIds();

      target.bind();
      target.clear(renderer.light().sky_color);
      if (mode == RenderMode::ItemBuffer) target.clear(Vec4(0.0f, 0.0f, 0.0f, 1.0f));
      OcclusionCuller culler(0.2);
      std::vector<DrawItem> rest;
      const OcclusionStats stats = culler.cull(
          camera, items, bounds, target,
          [&](std::span<const DrawItem> occluders) { renderer.draw(camera, occluders, target, mode); }, rest);
      renderer.draw(camera, rest, target, mode);
      EXPECT_EQ(stats.items, items.size());
      EXPECT_EQ(stats.occluders + stats.hidden + rest.size(), items.size());
      if (mode == RenderMode::Shaded) hidden += stats.hidden, hidden_triangles += stats.hidden_triangles;
      ASSERT_TRUE(target.readIds().pixels() == want_ids.pixels()) << "trial " << trial;
      ASSERT_TRUE(target.readColor().pixels() == want_color.pixels()) << "trial " << trial;
    }
  }
  // Not vacuous: in the canyon most towers are behind the walls.
  EXPECT_GT(hidden, 100u);
  EXPECT_GT(hidden_triangles, offered_triangles / 10);
}

// hidesWorldBox, used for things that are not draw items (an image cache's nodes): every object whose world box it
// calls hidden shows no pixel in the full frame's ids (brute force), also when every item was an occluder and the
// depth is read on first use.
TEST_F(OcclusionStreetTest, WorldBoxesCalledHiddenShowNoPixelOfTheFrame) {
  Renderer renderer;
  RenderTarget target(96, 64);
  std::mt19937 rng(9);
  size_t hidden = 0, hidden_all_occluders = 0, visible = 0;
  for (int trial = 0; trial < 30; ++trial) {
    const Camera camera = streetCamera(rng, false);
    std::vector<DrawItem> items;
    std::vector<Box3> bounds;
    gpu_scene_->appendDrawItems({}, items, camera, &bounds);
    renderer.render(camera, items, target, RenderMode::ItemBuffer);
    const image::IdImage ids = target.readIds();
    std::vector<bool> seen(scene_.objects.size() + 1, false);
    for (const uint32_t id : ids.pixels())
      if (id < seen.size()) seen[id] = true;

    const bool all_occluders = trial % 3 == 0;
    target.bind();
    target.clear(Vec4(0.0f, 0.0f, 0.0f, 1.0f));
    OcclusionCuller culler(all_occluders ? 1.0 : 0.2);
    std::vector<DrawItem> rest;
    culler.cull(
        camera, items, bounds, target,
        [&](std::span<const DrawItem> occluders) { renderer.draw(camera, occluders, target, RenderMode::ItemBuffer); },
        rest);
    for (const scene::Object& object : scene_.objects) {
      if (!culler.hidesWorldBox(object.world_bounds)) {
        visible += seen[object.id];
        continue;
      }
      EXPECT_FALSE(seen[object.id]) << "object " << object.id << " called hidden in trial " << trial;
      ++hidden;
      hidden_all_occluders += all_occluders;
    }
  }
  // Not vacuous: in the canyon most towers are behind the walls, on both paths.
  EXPECT_GT(hidden, 300u);
  EXPECT_GT(hidden_all_occluders, 100u);
  EXPECT_GT(visible, 100u);
}

}  // namespace
}  // namespace farfield::gpu
