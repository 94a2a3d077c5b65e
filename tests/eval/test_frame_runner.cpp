#include "farfield/eval/frame_runner.h"

#include <gtest/gtest.h>

#include <cmath>

#include "eval/eval_test_scenes.h"
#include "eval/mode_harness.h"
#include "farfield/core/error.h"
#include "farfield/gpu/context.h"
#include "farfield/image/metrics.h"
#include "farfield/scene/builtin.h"
#include "farfield/scene/bvh.h"

namespace farfield::eval {
namespace {

constexpr int kSize = 64;

// Everything a mode needs over builtin:cubes, on the shared headless context.
struct Harness : test::ModeHarness {
  Harness() : ModeHarness(kSize) {}
};

// Triangles of the objects whose world bounds intersect the camera's frustum: brute force over all objects.
uint64_t bruteForceVisibleTriangles(const scene::Scene& scene, const Camera& camera) {
  const Frustum frustum = Frustum::fromMatrix(camera.viewProjection());
  uint64_t triangles = 0;
  for (const scene::Object& object : scene.objects) {
    if (!frustum.intersects(object.world_bounds)) continue;
    for (const scene::Part& part : object.parts) triangles += scene.meshes[part.mesh].triangleCount();
  }
  return triangles;
}

size_t pixelsNotEqualTo(const image::ColorImage& img, const image::Rgba8& color) {
  size_t n = 0;
  for (const auto& p : img.pixels())
    if (p.r != color.r || p.g != color.g || p.b != color.b) ++n;
  return n;
}

TEST(CulledMode, SameImagesAsFullWithFewerTriangles) {
  Harness h;
  auto full = h.make("full");
  auto culled = h.make("culled-cpu");
  auto gpu_culled = h.make("culled");
  auto frustum = h.make("frustum");
  FrameRunner runner(*h.renderer, *h.target);
  const gen::CameraPath path = test::sideWalkPath(4);
  uint64_t all_triangles = 0;
  for (const auto& o : h.scene.objects)
    for (const auto& part : o.parts) all_triangles += h.scene.meshes[part.mesh].triangleCount();

  for (size_t i = 0; i < path.frames.size(); ++i) {
    SCOPED_TRACE("path frame " + std::to_string(i));
    const Camera camera = pathCamera(path, i, kSize, kSize);
    const FrameRecord f = runner.run(*full, camera, i);
    const image::ColorImage full_image = h.target->readColor();
    const FrameRecord c = runner.run(*culled, camera, i);
    const image::ColorImage culled_image = h.target->readColor();
    const FrameRecord fr = runner.run(*frustum, camera, i);
    const image::ColorImage frustum_image = h.target->readColor();
    const FrameRecord g = runner.run(*gpu_culled, camera, i);
    const image::ColorImage gpu_image = h.target->readColor();

    // The view shows geometry (so the comparison means something): most pixels are not the sky.
    const image::Rgba8 sky = full_image.at(kSize / 2, 0);
    EXPECT_GT(pixelsNotEqualTo(full_image, sky), size_t(kSize * kSize / 4));
    for (const image::ColorImage* image : {&culled_image, &frustum_image}) {
      const double psnr = image::psnr(full_image, *image);
      EXPECT_TRUE(std::isinf(psnr) || psnr > 50.0) << "PSNR " << psnr;
    }
    // Occlusion culling is exact: the frame of "culled-cpu" is the frame of "frustum", from fewer triangles or as
    // many; so is the GPU-driven frame of "culled" (this scene has no coplanar surfaces of different objects), from
    // a few multi-draws and without waiting for the GPU, where the CPU path read the occluders' depth back.
    EXPECT_TRUE(culled_image.pixels() == frustum_image.pixels());
    EXPECT_TRUE(gpu_image.pixels() == frustum_image.pixels());
    EXPECT_LE(c.triangles, fr.triangles);
    EXPECT_GT(g.triangles, 0u);
    EXPECT_LT(g.triangles, f.triangles);
    EXPECT_LT(g.objects, f.objects);
    ASSERT_TRUE(g.counted);
    EXPECT_EQ(g.syncs, 0u);
    EXPECT_GE(c.syncs, 1u);
    EXPECT_LE(g.draw_calls, 2 * h.context.arena().groups().size());
    EXPECT_LT(g.draw_calls, fr.draw_calls);

    EXPECT_EQ(f.triangles, all_triangles);
    EXPECT_EQ(f.objects, uint32_t(h.scene.objects.size()));
    EXPECT_LT(c.triangles, f.triangles);
    EXPECT_LT(c.objects, f.objects);
    // Frustum culling is conservative: everything whose bounds touch the frustum is drawn.
    EXPECT_LT(fr.triangles, f.triangles);
    EXPECT_GE(fr.triangles, bruteForceVisibleTriangles(h.scene, camera));
    EXPECT_GT(f.wall_ms, 0.0);
    EXPECT_GT(c.wall_ms, 0.0);
    EXPECT_EQ(c.path_frame, i);
  }
}

TEST(CulledMode, NothingInViewDrawsNothing) {
  Harness h;
  auto full = h.make("full");
  auto culled = h.make("culled-cpu");
  auto gpu_culled = h.make("culled");
  FrameRunner runner(*h.renderer, *h.target);
  gen::CameraPath path;
  path.frames.push_back(test::skyFrame());
  const Camera camera = pathCamera(path, 0, kSize, kSize);
  ASSERT_EQ(bruteForceVisibleTriangles(h.scene, camera), 0u);
  runner.run(*full, camera, 0);
  const image::ColorImage full_image = h.target->readColor();
  const FrameRecord c = runner.run(*culled, camera, 0);
  const image::ColorImage culled_image = h.target->readColor();
  // GpuScene::appendDrawItems reads an empty id list as "all objects"; the culled mode must not fall into that.
  EXPECT_EQ(c.triangles, 0u);
  EXPECT_EQ(c.draw_calls, 0u);
  EXPECT_TRUE(std::isinf(image::psnr(full_image, culled_image)));
  // The GPU-driven frame issues its multi-draws whatever they hold; none draws a triangle.
  const FrameRecord g = runner.run(*gpu_culled, camera, 0);
  EXPECT_EQ(g.triangles, 0u);
  EXPECT_EQ(g.objects, 0u);
  EXPECT_TRUE(std::isinf(image::psnr(full_image, h.target->readColor())));
}

// A mode that draws its frame itself in two passes (first the boxes, then the ground), as impostor modes will.
class TwoPassMode final : public Mode {
 public:
  std::string name() const override { return "test-two-pass"; }
  void prepare(const ModeContext& context) override {
    const auto all = context.gpu_scene->drawItems();
    for (const auto& item : all) (item.object_id == 1 ? second_ : first_).push_back(item);
  }
  void frame(FrameContext& frame) override {
    frame.drawPass(first_);
    frame.items() = second_;  // the main pass, drawn by the harness on top
  }

 private:
  std::vector<gpu::DrawItem> first_, second_;
};

TEST(FrameRunner, ModeWithOwnPassesMatchesFullAndIsCountedAndTimed) {
  Harness h;
  auto full = h.make("full");
  TwoPassMode two_pass;
  two_pass.prepare(h.context);
  FrameRunner runner(*h.renderer, *h.target);
  const gen::CameraPath path = test::sideWalkPath(2);
  for (size_t i = 0; i < path.frames.size(); ++i) {
    const Camera camera = pathCamera(path, i, kSize, kSize);
    // Leave a different picture in the target first: the two-pass frame must clear it.
    runner.run(*full, pathCamera(path, 1 - i, kSize, kSize), 1 - i);
    const FrameRecord t = runner.run(two_pass, camera, i);
    const image::ColorImage two_pass_image = h.target->readColor();
    const FrameRecord f = runner.run(*full, camera, i);
    const image::ColorImage full_image = h.target->readColor();
    EXPECT_TRUE(std::isinf(image::psnr(full_image, two_pass_image)));
    EXPECT_EQ(t.triangles, f.triangles);
    EXPECT_EQ(t.draw_calls, f.draw_calls);
    EXPECT_GT(t.wall_ms, 0.0);
    // GPU time on every frame, both paths (own passes: FrameRunner's timer; one pass: the renderer's), within the
    // frame's wall time.
    EXPECT_GT(t.gpu_ms, 0.0);
    EXPECT_LE(t.gpu_ms, t.wall_ms);
    EXPECT_GT(f.gpu_ms, 0.0);
    EXPECT_LE(f.gpu_ms, f.wall_ms);
  }
}

TEST(FrameRunner, BadCameraInPathIsAnError) {
  gen::CameraPath path = test::sideWalkPath(3);
  path.frames[1].at = path.frames[1].eye;
  EXPECT_NO_THROW(pathCamera(path, 0, kSize, kSize));
  try {
    pathCamera(path, 1, kSize, kSize);
    FAIL() << "no error for eye == at";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("frame 1"), std::string::npos) << e.what();
  }
  EXPECT_THROW(pathCamera(path, 3, kSize, kSize), Error);
}

}  // namespace
}  // namespace farfield::eval
