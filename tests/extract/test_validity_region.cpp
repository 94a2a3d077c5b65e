// Validity regions (extract/validity_region.h) against brute-force sampling of viewpoints: in the constructed street,
// a frame drawn the way the runtime draws it (an impostor where its region holds the viewpoint under the bound where
// the impostor appears in the frame, ErrorBound::angleWithin(frameRadius(...)); its
// objects as geometry elsewhere) keeps the parallax error under the bound at every sampled viewpoint of the street,
// across it and at other eye heights; drawing the impostors everywhere instead breaks the bound (so the regions are
// what keeps it), and the regions are not empty (impostors are still drawn beyond the capture point).
#include "farfield/extract/validity_region.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <limits>
#include <vector>

#include "extract/constructed_street.h"
#include "farfield/extract/pipeline_runner.h"
#include "farfield/core/error.h"
#include "farfield/core/error_bound.h"
#include "farfield/eval/parallax_error.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/renderer.h"
#include "farfield/impostor/drawable.h"

namespace farfield::extract {
namespace {

TEST(ValidityRegionOptions, BadOptionsAreErrors) {
  ValidityOptions even;
  even.laterals = 4;
  EXPECT_THROW(computeValidityRegion(Vec3(0, 0, 2), Vec3(10, 0, 2), 12.0f, {}, {}, {}, 0.1, even), Error);
  ValidityOptions zero_step;
  zero_step.step = 0.0f;
  EXPECT_THROW(computeValidityRegion(Vec3(0, 0, 2), Vec3(10, 0, 2), 12.0f, {}, {}, {}, 0.1, zero_step), Error);
  EXPECT_THROW(computeValidityRegion(Vec3(0, 0, 2), Vec3(10, 0, 2), 12.0f, {}, {}, {}, 0.0), Error);
}

// Without objects nothing can be wrong: the region covers the whole cell with a zero envelope.
TEST(ValidityRegionOptions, EmptyImpostorIsValidAlongTheWholeCell) {
  const impostor::ValidityRegion r = computeValidityRegion(Vec3(0, 0, 2), Vec3(10, 0, 2), 12.0f, {}, {}, {}, 0.1);
  ASSERT_EQ(r.laterals, ValidityOptions{}.laterals);
  ASSERT_EQ(r.samples(), 11u);
  EXPECT_EQ(*std::max_element(r.envelope.begin(), r.envelope.end()), 0.0f);
  EXPECT_TRUE(r.valid(Vec3(10, 5, 2), 0.0));
}

class ValidityRegionTest : public ::testing::Test {
 protected:
  void SetUp() override { gpu::sharedHeadlessContext(); }
};

TEST_F(ValidityRegionTest, RuntimeRuleKeepsTheBoundAtSampledViewpoints) {
  const test::Street s = test::constructedStreet();
  ASSERT_NE(s.cell, urban::kNone);
  const urban::CellMap cells(s.graph, s.scene);
  PipelineOptions options;
  options.base.resolution = 256;
  options.base.progress = false;
  options.frame_width = 256;
  options.frame_height = 256;
  options.frame_fov_deg = 60.0f;
  options.error_px = 10.0;
  options.grid_cells = 30;
  options.pvs.face_size = 64;
  options.pvs.spacing = 10.0f;
  const gpu::GpuScene gpu_scene(s.scene);
  PipelineRunner runner(s.scene, gpu_scene, cells, options);
  CellWork work = runner.start(s.cell);
  runner.runStages({kStagePvs, kStageNearFar, kStageSingle, kStageMmi}, work);
  const store::CellPipeline& r = work.result;
  ASSERT_TRUE(r.has_mmi && r.has_single);
  ASSERT_GE(r.layers.size(), 2u);
  for (const store::StoredLayer& layer : r.layers) ASSERT_FALSE(layer.validity.empty());
  ASSERT_FALSE(r.single.validity.empty());

  const ErrorBound bound{options.error_px, options.frame_width, options.frame_height, degToRad(60.0)};
  const double theta = bound.angle();
  // A layer (or the single mesh) as the runtime holds it: its objects and bounds, per station a region, per view
  // its impostor and station.
  struct Drawn {
    std::vector<uint32_t> objects;
    Box3 bounds;
    const std::vector<impostor::ValidityRegion>* regions = nullptr;
    std::vector<std::unique_ptr<impostor::GpuImpostor>> views;
    std::vector<uint32_t> stations;
  };
  const auto boundsOf = [&](const std::vector<uint32_t>& ids) {
    Box3 b;
    for (uint32_t id : ids) b.expand(s.scene.objects[id - 1].world_bounds);
    return b;
  };
  impostor::GpuImpostorOptions split;
  split.split_by_object_id = true;
  const auto drawn = [&](const store::StoredLayer& layer, const std::vector<impostor::DepthMeshImpostor>& views) {
    Drawn d;
    d.objects = layer.objects;
    d.bounds = boundsOf(layer.objects);
    d.regions = &layer.validity;
    EXPECT_EQ(views.size(), layer.views.size());
    for (size_t v = 0; v < views.size(); ++v) {
      d.views.push_back(std::make_unique<impostor::GpuImpostor>(views[v], split));
      d.stations.push_back(layer.views[v].station);
    }
    return d;
  };
  std::vector<Drawn> mmi, smi;
  size_t stations = 0;
  for (size_t l = 0; l < r.layers.size(); ++l) {
    mmi.push_back(drawn(r.layers[l], work.layer_views[l]));
    stations += r.layers[l].validity.size();
  }
  smi.push_back(drawn(r.single, work.single_views));

  std::vector<uint32_t> reference_ids{s.ground};
  reference_ids.insert(reference_ids.end(), r.far.begin(), r.far.end());
  std::vector<gpu::DrawItem> reference_items;
  gpu_scene.appendDrawItems(reference_ids, reference_items);
  // The runtime's rule (runtime/mmi_mode.cpp), or every impostor whatever its region (`ignore_regions`).
  size_t impostors_drawn_beyond_start = 0;
  auto frame_items = [&](const std::vector<Drawn>& set, const Camera& camera, bool ignore_regions, double s_along) {
    std::vector<uint32_t> geometry{s.ground};
    std::vector<gpu::DrawItem> items;
    for (const Drawn& d : set) {
      // The station with the smallest error under the bound where the layer appears, as runtime/mmi_mode.cpp does.
      const double limit = bound.angleWithin(frameRadius(camera, d.bounds));
      int station = -1;
      double best = std::numeric_limits<double>::infinity();
      for (size_t j = 0; j < d.regions->size(); ++j) {
        const double e = (*d.regions)[j].errorAt(camera.eye);
        if (e <= limit && e < best) {
          best = e;
          station = int(j);
        }
      }
      if (ignore_regions) station = 0;
      if (station >= 0) {
        for (size_t v = 0; v < d.views.size(); ++v)
          if (d.stations[v] == uint32_t(station)) d.views[v]->appendDrawItems(items);
        if (!ignore_regions && s_along >= 10.0) ++impostors_drawn_beyond_start;
      } else {
        geometry.insert(geometry.end(), d.objects.begin(), d.objects.end());
      }
    }
    std::sort(geometry.begin(), geometry.end());
    gpu_scene.appendDrawItems(geometry, items);
    return items;
  };

  gpu::Renderer renderer;
  gpu::RenderTarget target(options.frame_width, options.frame_height);
  const auto ids = [&](const Camera& camera, const std::vector<gpu::DrawItem>& items, gpu::RenderMode mode) {
    renderer.render(camera, items, target, mode);
    return target.readIds();
  };
  eval::ParallaxOptions metric;
  metric.ignore_ids = {s.ground};
  metric.percentile = 0.99;

  const float half_width = (*mmi[0].regions)[0].half_width;
  double worst_kept = 0.0, worst_ignored = 0.0;
  size_t viewpoints = 0;
  for (float along : {-1.5f, 0.0f, 10.0f, 20.0f, 30.0f, 40.0f, 50.0f})
    for (float across : {-half_width, 0.0f, half_width})
      for (float dz : {-0.5f, 0.0f, 0.25f}) {
        Camera camera = work.street_camera;
        camera.width = options.frame_width;
        camera.height = options.frame_height;
        const Vec3 forward = camera.at - camera.eye;
        camera.eye = work.p_eye + Vec3(along, across, dz);  // the cell runs along +x from (0, 0)
        camera.at = camera.eye + forward;
        const image::IdImage reference = ids(camera, reference_items, gpu::RenderMode::ItemBuffer);
        for (const std::vector<Drawn>* set : {&mmi, &smi}) {
          const double kept =
              eval::parallaxError(reference, ids(camera, frame_items(*set, camera, false, along), gpu::RenderMode::Shaded), metric)
                  .percentile_px;
          const double ignored =
              eval::parallaxError(reference, ids(camera, frame_items(*set, camera, true, along), gpu::RenderMode::Shaded), metric)
                  .percentile_px;
          EXPECT_LE(kept, options.error_px) << (set == &mmi ? "mmi" : "smi") << " at s " << along << " l " << across
                                            << " dz " << dz;
          worst_kept = std::max(worst_kept, kept);
          worst_ignored = std::max(worst_ignored, ignored);
        }
        ++viewpoints;
      }
  std::printf("%zu viewpoints: worst p99 parallax %.2f px with the regions, %.2f px drawing every impostor from the "
              "cell's start; %zu impostor draws 10 m or more into the cell; %zu layer stations for %zu layers; reach "
              "at the bound (stations' centreline):",
              viewpoints, worst_kept, worst_ignored, impostors_drawn_beyond_start, stations, r.layers.size());
  for (const Drawn& d : mmi)
    for (const impostor::ValidityRegion& region : *d.regions) std::printf(" %.0f m", region.reach(theta));
  std::printf("; smi:");
  for (const impostor::ValidityRegion& region : *smi[0].regions) std::printf(" %.0f m", region.reach(theta));
  std::printf("\n");
  EXPECT_GT(worst_ignored, options.error_px);  // the regions are what keeps the bound here
  EXPECT_GT(impostors_drawn_beyond_start, 0u);  // and they do not simply turn every impostor off
}

}  // namespace
}  // namespace farfield::extract
