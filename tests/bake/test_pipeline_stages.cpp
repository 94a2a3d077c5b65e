// What the stages build when run on the pipeline runner directly: six cube-face views layer the whole far set, and
// the single mesh is built by the single stage only.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "farfield/bake/pipeline.h"
#include "farfield/gpu/renderer.h"
#include "farfield/store/impostor_store.h"
#include "bake/pipeline_fixture.h"

namespace farfield::bake {
using namespace farfield::extract;
namespace {

using pipeline_test::BakedCity;
using pipeline_test::bakedCity;
using pipeline_test::PipelineBakeTest;
using pipeline_test::smallOptions;

// --views six: every layer gets the six 90-degree cube faces from the cell's start, so every far object of the PVS
// is layered (none is left out for lying outside a street view), and the six faces together show every layer
// object that the street view shows.
TEST_F(PipelineBakeTest, SixViewsLayerTheWholeFarSetAndCoverTheStreetView) {
  const BakedCity& b = bakedCity();
  const gpu::GpuScene gpu_scene(b.city.scene);
  PipelineOptions six = smallOptions();
  six.views = LayerViews::Six;
  PipelineRunner six_runner(b.city.scene, gpu_scene, *b.cells, six);
  PipelineRunner street_runner(b.city.scene, gpu_scene, *b.cells, smallOptions());
  const std::vector<std::string> stages{kStagePvs, kStageNearFar, kStageSingle, kStageMmi};
  size_t six_layered = 0, street_layered = 0;
  for (uint32_t cell : b.visited) {
    SCOPED_TRACE("cell " + std::to_string(cell));
    CellWork w6 = six_runner.start(cell), w1 = street_runner.start(cell);
    six_runner.runStages(stages, w6);
    street_runner.runStages(stages, w1);
    std::vector<uint32_t> layered;
    for (const store::StoredLayer& l : w6.result.layers) {
      ASSERT_EQ(l.views.size(), 6u * l.validity.size());  // six cube faces per station
      for (const store::StoredView& v : l.views) {
        EXPECT_NEAR(v.camera.fov_y, float(kPi / 2.0), 1e-6f);
        EXPECT_EQ(v.camera.eye, l.validity.at(v.station).origin);
        if (v.station == 0) {
          EXPECT_EQ(v.camera.eye, w6.street_camera.eye);
        }
      }
      layered.insert(layered.end(), l.objects.begin(), l.objects.end());
    }
    std::sort(layered.begin(), layered.end());
    EXPECT_EQ(layered, w6.result.far);  // all of the far set, each object once
    six_layered += layered.size();
    // The single mesh: every object with a fair number of pixels in the street view's image (captured with the far
    // objects that view meets) has pixels in some cube face (captured with all far objects from the same eye: an
    // occluder inside the street view's frustum meets it, so it was drawn there too). Faces are coarser (90 degrees
    // over the same pixels: a sliver of 34 pixels in the street view was measured to vanish), hence the margin of
    // 100 pixels.
    std::map<uint32_t, size_t> street_pixels;
    std::set<uint32_t> in_faces;
    // Station 0 of both (the cell's start; the other stations are kept or dropped by their own validity).
    for (size_t k = 0; k < w6.single_views.size(); ++k) {
      const impostor::DepthMeshImpostor& v = w6.single_views[k];
      if (w6.result.single.views[k].station == 0 && v.ids)
        for (uint32_t id : v.ids->pixels()) in_faces.insert(id);
    }
    for (size_t k = 0; k < w1.single_views.size(); ++k) {
      const impostor::DepthMeshImpostor& v = w1.single_views[k];
      if (w1.result.single.views[k].station != 0) continue;
      street_layered += v.empty() ? 0 : 1;
      if (v.ids)
        for (uint32_t id : v.ids->pixels()) ++street_pixels[id];
    }
    for (const auto& [id, pixels] : street_pixels) {
      if (id != 0 && pixels >= 100) {
        EXPECT_TRUE(in_faces.count(id)) << "object " << id << " (" << pixels << " px)";
      }
    }
  }
  EXPECT_GT(six_layered, 0u);
  EXPECT_GT(street_layered, 0u);
}

// The single mesh is the single stage's: with mmi after it, the same record as single alone (built once, by single),
// and mmi alone builds none.
TEST_F(PipelineBakeTest, TheSingleMeshIsBuiltByTheSingleStageOnly) {
  const BakedCity& b = bakedCity();
  const gpu::GpuScene gpu_scene(b.city.scene);
  PipelineRunner runner(b.city.scene, gpu_scene, *b.cells, smallOptions());
  const uint32_t cell = b.visited.front();
  CellWork alone = runner.start(cell), both = runner.start(cell), mmi = runner.start(cell);
  runner.runStages({kStageNearFar, kStageSingle}, alone);
  runner.runStages({kStageNearFar, kStageSingle, kStageMmi}, both);
  runner.runStages({kStageNearFar, kStageMmi}, mmi);
  ASSERT_TRUE(alone.result.has_single && both.result.has_single && both.result.has_mmi);
  EXPECT_FALSE(alone.result.has_mmi);
  EXPECT_TRUE(alone.result.layers.empty());
  EXPECT_FALSE(mmi.result.has_single);
  EXPECT_TRUE(mmi.result.single.views.empty());
  EXPECT_TRUE(mmi.single_views.empty());
  ASSERT_FALSE(alone.result.single.views.empty());
  EXPECT_EQ(alone.result.single.objects, both.result.single.objects);
  ASSERT_EQ(alone.result.single.views.size(), both.result.single.views.size());
  ASSERT_EQ(alone.single_views.size(), both.single_views.size());
  for (size_t v = 0; v < alone.result.single.views.size(); ++v) {
    EXPECT_EQ(alone.result.single.views[v].triangles, both.result.single.views[v].triangles);
    EXPECT_EQ(alone.result.single.views[v].station, both.result.single.views[v].station);
  }
  ASSERT_EQ(alone.result.single.validity.size(), both.result.single.validity.size());
  for (size_t j = 0; j < alone.result.single.validity.size(); ++j)
    EXPECT_EQ(alone.result.single.validity[j].envelope, both.result.single.validity[j].envelope);
  // The layers do not depend on whether the single stage ran.
  ASSERT_EQ(both.result.layers.size(), mmi.result.layers.size());
  for (size_t l = 0; l < both.result.layers.size(); ++l)
    EXPECT_EQ(both.result.layers[l].objects, mmi.result.layers[l].objects);
}

}  // namespace
}  // namespace farfield::bake
