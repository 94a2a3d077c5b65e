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

// The grid behind a long wall (larger than max_object_radius, so always geometry, and the occluder; reaching below
// the frame, so that the depth pyramid's coarse texels over the grid hold only the wall), and an eye behind the wall
// from which it hides about half of the grid.
scene::Scene gridBehindWall() {
  scene::Scene s = grid();
  scene::Material m;
  m.base_color = Vec4(0.7f, 0.6f, 0.5f, 1.0f);
  scene::Object wall;
  wall.parts.push_back({s.addMesh(scene::makeBox(Vec3(-300, -81, -20), Vec3(24, -80, 12))), s.addMaterial(m)});
  s.addObject(wall);
  s.updateBounds();
  return s;
}

Camera behindWallCamera() {
  Camera cam;
  cam.eye = Vec3(20, -100, 3);
  cam.at = Vec3(30, 30, 3);
  cam.width = 320;
  cam.height = 180;
  return cam;
}

// An eye outside the grid's corner, looking at its middle.
Camera gridCamera(int width, int height) {
  Camera cam;
  cam.eye = Vec3(-120, -140, 40);
  cam.at = Vec3(35, 35, 0);
  cam.width = width;
  cam.height = height;
  return cam;
}

TEST(ImageCacheGl, ReusesRegeneratesAndFallsBackUnderTheBudget) {
  gpu::sharedHeadlessContext();
  const scene::Scene s = grid();
  const gpu::GpuScene gs(s);
  gpu::Renderer renderer;
  const Camera cam = gridCamera(320, 180);
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
  tight.lost_frame_investment = 0.0;
  // The second frame from the same eye: the first (no speed known yet) expects no reuse of any image.
  auto secondFrame = [&](const ImageCacheOptions& options) {
    ImageCache cache(s, gs, options);
    items.clear();
    cache.frame(renderer, cam, 0, items);
    items.clear();
    return cache.frame(renderer, cam, 1, items);
  };
  const ImageCacheFrameStats none = secondFrame(tight);
  EXPECT_TRUE(none.lost);
  EXPECT_EQ(none.regenerations, 0u);
  EXPECT_GT(none.geometry_nodes, 0u);
  // The same lost frame with an investment still makes the images that pay back over their reuse (a node of 4
  // objects: 2 ms of geometry, against 2.3 ms to regenerate it and 0.5 ms to draw its image; the eye at rest).
  tight.cost.ms_per_draw = 0.5;
  tight.cost.base_ms = 100.0;
  tight.lost_frame_investment = 1.0;
  const ImageCacheFrameStats some = secondFrame(tight);
  EXPECT_TRUE(some.lost);
  EXPECT_GT(some.regenerations, 0u);
  std::printf("image cache: %zu regenerations, PSNR %.1f dB at the capture eye; %zu after moving 18 m\n",
              first.regenerations, psnr, later.regenerations);
  o.error_px = 0.0;
  EXPECT_THROW(ImageCache(s, gs, o), Error);
}

// Pay-back: a regeneration is taken only when the frames the new image is expected to serve (the eye's
// displacement its images stay valid over, divided by the eye's speed) save more than it costs. With a dear capture
// (50 ms of overhead against 0.5 ms of geometry per box), the first frame (no speed known: no reuse) draws
// geometry; a next frame from a still eye makes the images; a next frame 85 m away makes none, which a
// cache without the rule does.
TEST(ImageCacheGl, ImagesAreMadeWhenTheyPayOverTheFramesTheEyeLeavesThemValid) {
  gpu::sharedHeadlessContext();
  const scene::Scene s = grid();
  const gpu::GpuScene gs(s);
  gpu::Renderer renderer;
  const Camera a = gridCamera(320, 180);
  Camera still = a, far = a;
  still.eye += Vec3(0.01f, 0.0f, 0.0f);
  far.eye += Vec3(60.0f, -60.0f, 0.0f);
  ImageCacheOptions o;
  o.error_px = 1.0;
  o.leaf_objects = 4;
  o.cost.ms_per_draw = 0.5;
  o.regeneration_overhead_ms = 50.0;
  std::vector<gpu::DrawItem> items;
  auto secondFrame = [&](const ImageCacheOptions& options, const Camera& next, ImageCacheFrameStats& first) {
    ImageCache cache(s, gs, options);
    items.clear();
    first = cache.frame(renderer, a, 0, items);
    items.clear();
    return cache.frame(renderer, next, 1, items);
  };
  ImageCacheFrameStats first;
  const ImageCacheFrameStats after_still = secondFrame(o, still, first);
  EXPECT_EQ(first.regenerations, 0u);
  EXPECT_GT(first.geometry_nodes, 0u);
  EXPECT_GT(after_still.regenerations, 0u);
  const ImageCacheFrameStats after_far = secondFrame(o, far, first);
  EXPECT_EQ(after_far.regenerations, 0u);
  EXPECT_GT(after_far.geometry_nodes, 0u);
  o.pay_back = false;
  EXPECT_GT(secondFrame(o, far, first).regenerations, 0u);
}

// The layered kind's regenerations are scheduled with the calibrated capture and draw bounds: a capture that costs
// more than the budget per layer is never started (the nodes are drawn as geometry, counted), a cheap one is, and the
// prediction of a scheduled frame stays under t_max and equals the scheduler's sum.
TEST(ImageCacheGl, LayeredRegenerationsKeepTheCalibratedBudget) {
  gpu::sharedHeadlessContext();
  const scene::Scene s = grid();
  const gpu::GpuScene gs(s);
  gpu::Renderer renderer;
  const Camera cam = gridCamera(160, 90);
  ImageCacheOptions o;
  o.kind = CachedImageKind::Layered;
  o.error_px = 2.0;
  o.leaf_objects = 4;
  o.t_max_ms = 100.0;
  o.cost.ms_per_draw = 0.01;
  o.layered_cost.calibrated = true;
  o.layered_cost.capture.ms_per_draw = 1000.0;  // per layer: no capture fits 100 ms
  o.pay_back = false;  // the budget alone decides here (pay-back: ImagesAreMadeWhenTheyPay...)
  std::vector<gpu::DrawItem> items;
  ImageCache dear(s, gs, o);
  const ImageCacheFrameStats none = dear.frame(renderer, cam, 0, items);
  EXPECT_EQ(none.regenerations, 0u);
  EXPECT_GT(none.geometry_nodes, 0u);
  EXPECT_LE(none.predicted_ms, o.t_max_ms);

  o.layered_cost.capture.ms_per_draw = 1.0;  // 1 ms a layer, 4 ms a filled megapixel of quads
  o.layered_cost.draw.ms_per_mpixel = 4.0;
  o.t_max_ms = 30.0;
  ImageCache cheap(s, gs, o);
  items.clear();
  const ImageCacheFrameStats some = cheap.frame(renderer, cam, 0, items);
  EXPECT_GT(some.regenerations, 0u);
  EXPECT_LE(some.predicted_ms, o.t_max_ms);
  // Without a budget more (or as many) nodes are regenerated, at a predicted cost over what the budget allowed.
  o.t_max_ms = 0.0;
  ImageCache free(s, gs, o);
  items.clear();
  const ImageCacheFrameStats all = free.frame(renderer, cam, 0, items);
  EXPECT_GE(all.regenerations, some.regenerations);
  EXPECT_EQ(all.geometry_nodes + all.regenerations, some.geometry_nodes + some.regenerations);
  if (all.regenerations > some.regenerations) {
    EXPECT_GT(all.predicted_ms, 30.0);
  }
  o.cost_safety_factor = 0.5;
  EXPECT_THROW(ImageCache(s, gs, o), Error);
}

// Occlusion culling inside the cache's frame: the wall of gridBehindWall hides about half of the grid. Nodes behind
// it are neither regenerated nor drawn, the frame stays as close to the full-geometry frame as the frame without
// occlusion culling, and with the wall removed from the view nothing is hidden.
TEST(ImageCacheGl, OcclusionSkipsNodesHiddenBehindNearGeometry) {
  gpu::sharedHeadlessContext();
  const scene::Scene s = gridBehindWall();
  const gpu::GpuScene gs(s);
  gpu::Renderer renderer;
  const Camera cam = behindWallCamera();
  ImageCacheOptions o;
  o.error_px = 1.0;
  o.leaf_objects = 2;
  o.min_distance_radii = 6.0;  // small nodes: some wholly behind the wall
  gpu::RenderTarget target(cam.width, cam.height);
  renderer.render(cam, gs.drawItems(), target);
  const image::ColorImage reference = target.readColor();

  auto run = [&](const Camera& camera, bool occlusion, ImageCacheFrameStats& st) {
    ImageCache cache(s, gs, o);
    std::vector<gpu::DrawItem> items;
    renderer.render(camera, {}, target);  // clears
    ImageCacheOcclusion occ;
    occ.target = &target;
    occ.occluder_share = 0.1;
    occ.draw_occluders = [&](std::span<const gpu::DrawItem> occluders) { renderer.draw(camera, occluders, target); };
    st = cache.frame(renderer, camera, 0, items, occlusion ? &occ : nullptr);
    renderer.draw(camera, items, target);
    return target.readColor();
  };
  ImageCacheFrameStats plain, culled;
  const image::ColorImage without = run(cam, false, plain);
  const image::ColorImage with = run(cam, true, culled);
  EXPECT_EQ(plain.hidden_nodes, 0u);
  EXPECT_GT(culled.occluders, 0u);
  EXPECT_GT(culled.hidden_nodes, 0u);
  EXPECT_GT(culled.hidden_node_triangles, 0u);
  // What is hidden needs no image: fewer regenerations, and every node is either hidden, an image or geometry.
  EXPECT_LT(culled.regenerations, plain.regenerations);
  EXPECT_EQ(culled.regenerations + culled.geometry_nodes + culled.hidden_nodes,
            plain.regenerations + plain.geometry_nodes);
  const double psnr_without = image::psnr(without, reference), psnr_with = image::psnr(with, reference);
  EXPECT_GT(psnr_with, 30.0);
  EXPECT_GE(psnr_with, psnr_without - 0.5);
  std::printf("image cache occlusion: %zu of %zu nodes hidden, %zu regenerations instead of %zu; PSNR %.1f dB "
              "(%.1f without)\n",
              culled.hidden_nodes, plain.regenerations + plain.geometry_nodes, culled.regenerations,
              plain.regenerations, psnr_with, psnr_without);

  // Seen from above the wall, nothing of the grid is behind it.
  Camera above = cam;
  above.eye = Vec3(20, -100, 90);
  ImageCacheFrameStats open;
  run(above, true, open);
  EXPECT_EQ(open.hidden_nodes, 0u);
  EXPECT_GT(open.regenerations, 0u);
}

// Nodes drawn as geometry (no regeneration allowed) behind the wall, large nodes that reach out beside it:
// occlusion culling drops their items behind the wall, the frame is pixel-identical to the one drawn without it (an
// exact cull), it draws fewer triangles, and the prediction counts only what is drawn.
TEST(ImageCacheGl, NodesDrawnAsGeometryCostOnlyWhatTheOccludersLeave) {
  gpu::sharedHeadlessContext();
  const scene::Scene s = gridBehindWall();
  const gpu::GpuScene gs(s);
  gpu::Renderer renderer;
  const Camera cam = behindWallCamera();
  ImageCacheOptions o;
  o.error_px = 1.0;
  o.leaf_objects = 1;
  o.min_distance_radii = 1.2;     // large nodes, partly behind the wall
  o.max_regenerations = 0;        // every node of the cut is drawn as geometry
  o.cost.ms_per_mtriangle = 1000.0;
  gpu::RenderTarget target(cam.width, cam.height);
  auto run = [&](bool occlusion, ImageCacheFrameStats& st, uint64_t& triangles) {
    ImageCache cache(s, gs, o);
    std::vector<gpu::DrawItem> items;
    renderer.render(cam, {}, target, gpu::RenderMode::ItemBuffer);  // clears
    ImageCacheOcclusion occ;
    occ.target = &target;
    occ.occluder_share = 0.1;
    occ.draw_occluders = [&](std::span<const gpu::DrawItem> occluders) {
      renderer.draw(cam, occluders, target, gpu::RenderMode::ItemBuffer);
      for (const gpu::DrawItem& it : occluders) triangles += it.triangleCount();
    };
    st = cache.frame(renderer, cam, 0, items, occlusion ? &occ : nullptr);
    renderer.draw(cam, items, target, gpu::RenderMode::ItemBuffer);
    for (const gpu::DrawItem& it : items) triangles += it.triangleCount();
    return target.readIds().pixels();
  };
  ImageCacheFrameStats plain, culled;
  uint64_t plain_triangles = 0, culled_triangles = 0;
  const std::vector<uint32_t> without = run(false, plain, plain_triangles);
  const std::vector<uint32_t> with = run(true, culled, culled_triangles);
  ASSERT_EQ(plain.regenerations, 0u);
  ASSERT_GT(culled.geometry_nodes, 0u);
  EXPECT_GT(culled.hidden_fallback_items, 0u);
  EXPECT_GT(culled.hidden_fallback_triangles, 0u);
  EXPECT_EQ(with, without);
  EXPECT_LT(culled_triangles, plain_triangles);
  // The prediction is what is drawn (1000 ms per million triangles, nothing else: 1 ms per 1000).
  EXPECT_NEAR(plain.predicted_ms, 1e-3 * double(plain_triangles), 1e-9 * plain.predicted_ms);
  EXPECT_NEAR(culled.predicted_ms, 1e-3 * double(culled_triangles), 1e-9 * plain.predicted_ms);
  std::printf("nodes as geometry: %zu of their items hidden (%llu triangles); %llu triangles drawn instead of %llu\n",
              culled.hidden_fallback_items, (unsigned long long)culled.hidden_fallback_triangles,
              (unsigned long long)culled_triangles, (unsigned long long)plain_triangles);
}

}  // namespace
}  // namespace farfield::runtime
