// Multi-mesh impostors against the single mesh (Decoret et al. 1999, sections 3-4): in a constructed scene, along the
// cell, the MMI's parallax error stays under the pixel threshold while the single mesh exceeds it, measured from
// object-id renders (eval/parallax_error.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "farfield/bake/pipeline.h"
#include "farfield/core/error_bound.h"
#include "farfield/eval/parallax_error.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/renderer.h"
#include "farfield/image/png_io.h"
#include "farfield/impostor/drawable.h"
#include "farfield/scene/builtin.h"
#include "extract/constructed_street.h"
#include "support/test_support.h"

namespace farfield::bake {
using namespace farfield::extract;
namespace {

class MmiParallaxTest : public ::testing::Test {
 protected:
  void SetUp() override { gpu::sharedHeadlessContext(); }
};

TEST_F(MmiParallaxTest, MmiStaysUnderThePixelThresholdAlongTheCellWhileTheSingleMeshExceedsIt) {
  const test::Street s = test::constructedStreet();
  ASSERT_NE(s.cell, urban::kNone);
  const urban::CellMap cells(s.graph, s.scene);
  // The segmentation the test relies on: the ground shared, L local, the four buildings distant.
  ASSERT_EQ(cells.assignment().shared, (std::vector<uint32_t>{s.ground}));
  ASSERT_EQ(cells.localObjects(s.cell), (std::vector<uint32_t>{s.ground, s.local}));

  PipelineOptions options;
  options.base.resolution = 256;
  options.base.fov_deg = 60.0f;
  options.base.progress = false;
  options.frame_width = 256;
  options.frame_height = 256;
  options.frame_fov_deg = 60.0f;
  options.error_px = 10.0;  // T = 10 px at the corners of 256 x 256 frames at 60 degrees = 0.0271 rad
  options.mesh = LayerMesh::Grid;
  options.grid_cells = 30;
  options.views = LayerViews::Street;
  options.station_spacing = 0.0f;  // the paper's one capture per cell
  options.pvs.face_size = 64;
  options.pvs.spacing = 10.0f;

  const gpu::GpuScene gpu_scene(s.scene);
  PipelineRunner runner(s.scene, gpu_scene, cells, options);
  CellWork work = runner.start(s.cell);
  runner.runStages({kStagePvs, kStageNearFar, kStageSingle, kStageMmi}, work);

  const store::CellPipeline& r = work.result;
  ASSERT_TRUE(r.has_pvs && r.has_split && r.has_single && r.has_mmi);
  EXPECT_EQ(r.far, (std::vector<uint32_t>{s.near_left, s.far_left, s.near_right, s.far_right}));
  // The test is only meaningful when each near building and the one it hides are in different layers, which they
  // must be: their visibility-event weight is far above T.
  const auto layer_of = [&](uint32_t id) {
    for (size_t l = 0; l < r.layers.size(); ++l)
      if (std::binary_search(r.layers[l].objects.begin(), r.layers[l].objects.end(), id)) return int(l);
    return -1;
  };
  ASSERT_GE(r.layers.size(), 2u);
  EXPECT_GT(r.max_weight_rad, runner.threshold());
  EXPECT_NEAR(runner.threshold(), (ErrorBound{10.0, 256, 256, degToRad(60.0)}).angle(), 1e-12);
  for (uint32_t id : r.far) ASSERT_GE(layer_of(id), 0) << "object " << id << " is in no layer";
  EXPECT_NE(layer_of(s.near_left), layer_of(s.far_left));
  EXPECT_NE(layer_of(s.near_right), layer_of(s.far_right));
  ASSERT_EQ(work.layer_views.size(), r.layers.size());
  ASSERT_EQ(work.single_views.size(), 1u);
  EXPECT_EQ(r.single.objects, r.far);

  // The impostors with per-object ids, and the geometry they stand for.
  impostor::GpuImpostorOptions split;
  split.split_by_object_id = true;
  std::vector<impostor::GpuImpostor> layers;
  for (const auto& views : work.layer_views) {
    ASSERT_EQ(views.size(), 1u);
    ASSERT_FALSE(views[0].triangle_ids.empty());
    layers.emplace_back(views[0], split);
  }
  const impostor::GpuImpostor single(work.single_views[0], split);
  std::vector<uint32_t> reference_ids{s.ground};  // the ground is geometry in every frame, impostors or not
  reference_ids.insert(reference_ids.end(), r.far.begin(), r.far.end());
  std::vector<gpu::DrawItem> reference_items, mmi_items, smi_items;
  gpu_scene.appendDrawItems(reference_ids, reference_items);
  gpu_scene.appendDrawItems(std::vector<uint32_t>{s.ground}, mmi_items);
  smi_items = mmi_items;
  for (const impostor::GpuImpostor& layer : layers) layer.appendDrawItems(mmi_items);
  single.appendDrawItems(smi_items);

  gpu::Renderer renderer;
  gpu::RenderTarget target(options.frame_width, options.frame_width);
  // The impostors are drawn Shaded, the way the viewer sees them, and their ids read from that pass: the texture's
  // alpha cuts the grid triangles that overhang a silhouette (a 30 x 30 grid's cells are 8.5 px wide), so only what
  // the viewer sees counts. An ItemBuffer pass samples no texture and would count those overhangs as well (measured:
  // 8 px at P for both impostors, MMI 16 px at Q). The reference is geometry: its ItemBuffer ids are exact.
  const auto ids = [&](const Camera& camera, const std::vector<gpu::DrawItem>& items, gpu::RenderMode mode) {
    renderer.render(camera, items, target, mode);
    return target.readIds();
  };
  eval::ParallaxOptions metric;
  metric.ignore_ids = {s.ground};
  metric.percentile = 0.99;

  const std::string dir = test::scratchDir("mmi_parallax").string();
  const int samples = 6;
  double worst_mmi = 0.0, worst_smi = 0.0;
  for (int i = 0; i < samples; ++i) {
    const float t = float(i) / float(samples - 1);
    Camera camera = work.street_camera;  // the bake's field of view, planes and image size
    camera.width = camera.height = options.frame_width;
    const Vec3 forward = camera.at - camera.eye;
    camera.eye = work.p_eye + t * (work.q_eye - work.p_eye);
    camera.at = camera.eye + forward;

    const image::IdImage reference = ids(camera, reference_items, gpu::RenderMode::ItemBuffer);
    const image::IdImage mmi = ids(camera, mmi_items, gpu::RenderMode::Shaded);
    const image::IdImage smi = ids(camera, smi_items, gpu::RenderMode::Shaded);
    const eval::ParallaxError e_mmi = eval::parallaxError(reference, mmi, metric);
    const eval::ParallaxError e_smi = eval::parallaxError(reference, smi, metric);
    std::printf("t=%.1f  MMI: p99 %6.2f max %6.2f mean %5.2f px, %5zu px mismatched | "
                "SMI: p99 %6.2f max %6.2f mean %5.2f px, %5zu px mismatched\n",
                double(t), e_mmi.percentile_px, e_mmi.max_px, e_mmi.mean_px, e_mmi.mismatched,
                e_smi.percentile_px, e_smi.max_px, e_smi.mean_px, e_smi.mismatched);
    const std::string stem = dir + "/t" + std::to_string(i);
    image::writeIdPng(stem + "_reference.png", reference);
    image::writeIdPng(stem + "_mmi.png", mmi);
    image::writeIdPng(stem + "_smi.png", smi);

    // The 99th percentile, not the maximum: the MMI's largest displacements are not visibility events between
    // objects but the grid mesh's depth inside one object. The near-left building's street-side face is seen at a
    // grazing angle from P (about 6 px wide in the capture, less than one 8.5 px grid cell) and about 85 px wide
    // from Q; the depth interpolated across it puts the face's foot a little off, so the ground (geometry) hides a
    // sliver of it (measured at Q: 8 px at most, 99.9th percentile 7.7 px; 18 px with LayerMesh::DepthMesh, whose
    // triangles cut across the building's corner).
    EXPECT_LE(e_mmi.percentile_px, options.error_px) << "MMI at t = " << t;
    if (i == 0) {  // at the creation viewpoint both impostors are exact up to sampling: what follows is parallax
      EXPECT_LE(e_mmi.max_px, 3.0);
      EXPECT_LE(e_smi.max_px, 3.0);
    }
    worst_mmi = std::max(worst_mmi, e_mmi.percentile_px);
    worst_smi = std::max(worst_smi, e_smi.percentile_px);
  }
  // The single mesh has no layer behind the near buildings: what they uncover is rubber sheet or nothing.
  EXPECT_GT(worst_smi, options.error_px);
  EXPECT_GT(worst_smi, 2.0 * worst_mmi);
}

}  // namespace
}  // namespace farfield::bake
