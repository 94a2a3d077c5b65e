// runtime/image_cache.h (GL): far nodes become images that the next frame from the same eye reuses; moving the eye
// far enough makes the metric ask for regenerations; a budget too small for any regeneration draws the invalid
// nodes as geometry; and the frame from the capture eye looks like the full-geometry frame.
#include "farfield/runtime/image_cache.h"

#include <gtest/gtest.h>

#include "farfield/core/error.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/render_target.h"
#include "farfield/image/metrics.h"
#include "farfield/scene/builtin.h"

namespace farfield::runtime {
namespace {

scene::Scene grid() {
  scene::Scene s;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) {
      scene::Material m;
      m.base_color = Vec4(0.2f + 0.12f * float(i), 0.3f + 0.1f * float(j), 0.5f, 1.0f);
      scene::Object o;
      const Vec3 lo(float(i) * 12.0f, float(j) * 12.0f, 0.0f);
      o.parts.push_back({s.addMesh(scene::makeBox(lo, lo + Vec3(6.0f, 6.0f, 4.0f + float((i * 7 + j) % 5)))),
                         s.addMaterial(m)});
      s.addObject(o);
    }
  s.updateBounds();
  return s;
}

TEST(ImageCacheGl, ReusesRegeneratesAndFallsBackUnderTheBudget) {
  gpu::sharedHeadlessContext();
  const scene::Scene s = grid();
  const gpu::GpuScene gs(s);
  gpu::Renderer renderer;
  Camera cam;
  cam.eye = Vec3(-120, -140, 40);
  cam.at = Vec3(35, 35, 0);
  cam.width = 320;
  cam.height = 180;
  ImageCacheOptions o;
  o.metric = impostor::ValidityMetric::Shade;
  o.error_px = 1.0;
  o.leaf_objects = 4;
  ImageCache cache(s, gs, o);
  std::vector<gpu::DrawItem> items;
  const ImageCacheFrameStats first = cache.frame(renderer, cam, 0, items);
  EXPECT_GT(first.regenerations, 0u);
  EXPECT_EQ(first.images_drawn, first.regenerations);
  EXPECT_GT(first.texture_bytes, 0u);

  gpu::RenderTarget target(cam.width, cam.height);
  renderer.render(cam, items, target);
  const image::ColorImage cached = target.readColor();
  renderer.render(cam, gs.drawItems(), target);
  const double psnr = image::psnr(cached, target.readColor());
  EXPECT_GT(psnr, 30.0);

  // The same frame index again repeats that frame's work (a bench's repeated timing of one frame).
  items.clear();
  EXPECT_EQ(cache.frame(renderer, cam, 0, items).regenerations, first.regenerations);
  items.clear();
  const ImageCacheFrameStats again = cache.frame(renderer, cam, 1, items);
  EXPECT_EQ(again.regenerations, 0u);
  EXPECT_EQ(again.images_drawn, first.images_drawn);

  Camera moved = cam;
  moved.eye += Vec3(15, -10, 0);
  items.clear();
  const ImageCacheFrameStats later = cache.frame(renderer, moved, 2, items);
  EXPECT_GT(later.regenerations, 0u);

  ImageCacheOptions tight = o;
  tight.cost.base_ms = 10.0;
  tight.cost.ms_per_draw = 0.01;
  tight.t_max_ms = 5.0;  // less than the frame's base: no regeneration fits
  ImageCache starved(s, gs, tight);
  items.clear();
  const ImageCacheFrameStats none = starved.frame(renderer, cam, 0, items);
  EXPECT_EQ(none.regenerations, 0u);
  EXPECT_GT(none.geometry_nodes, 0u);
  std::printf("image cache: %zu regenerations, PSNR %.1f dB at the capture eye; %zu after moving 18 m\n",
              first.regenerations, psnr, later.regenerations);
  o.error_px = 0.0;
  EXPECT_THROW(ImageCache(s, gs, o), Error);
}

}  // namespace
}  // namespace farfield::runtime
