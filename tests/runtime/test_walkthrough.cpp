// runtime::Walkthrough driven the way an engine drives it, without the benchmark harness: a small baked city, the
// plan of every frame of a drive rendered with the renderer. Under a bound no impostor keeps, every layer is drawn as
// geometry and the frame is exactly the geometry of the cell's near and layered objects; under the bake's bound some
// layers are impostors, each inside its region (error under the bound reported with it); bad options are errors.
#include "farfield/runtime/walkthrough.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <utility>

#include <algorithm>
#include <variant>

#include "farfield/bake/bake.h"
#include "farfield/bake/pipeline.h"
#include "farfield/core/error.h"
#include "farfield/gen/city.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/gpu_culler.h"
#include "farfield/gpu/render_target.h"
#include "support/test_support.h"

namespace farfield::runtime {
namespace {

struct BakedCity {
  gen::City city;
  std::unique_ptr<urban::CellMap> cells;
  gen::CameraPath path;
  std::string store;
};

const BakedCity& bakedCity() {
  static const BakedCity* s = [] {
    auto* c = new BakedCity;
    gen::CityOptions o;
    o.blocks = 16;
    o.detail = 0;
    o.seed = 5;
    c->city = gen::generateCity(o);
    c->cells = std::make_unique<urban::CellMap>(c->city.streets, c->city.scene);
    gen::StreetWalkOptions walk;
    walk.frames = 10;
    walk.walker = gen::Walker::Car;
    walk.fps = 2.0f;
    walk.seed = 4;
    c->path = gen::streetWalk(c->city.streets, walk);
    extract::PipelineOptions options;
    options.base.resolution = 192;
    options.base.progress = false;
    options.pvs.spacing = 8.0f;
    options.pvs.face_size = 64;
    c->store = test::scratchDir("walkthrough_store").string();
    bake::bakePipeline(gpu::sharedHeadlessContext(), c->city.scene, *c->cells, bake::cellsOnPath(*c->cells, c->path),
                       extract::parsePipeline("pvs,near-far,mmi"), options, c->store);
    return c;
  }();
  return *s;
}

class WalkthroughTest : public ::testing::Test {
 protected:
  void SetUp() override { gpu::sharedHeadlessContext(); }
};

TEST_F(WalkthroughTest, WhereNoImpostorIsValidThePlanIsTheGeometryOfTheCell) {
  const BakedCity& s = bakedCity();
  const scene::Scene& scene = s.city.scene;
  const gpu::GpuScene gpu_scene(scene);
  const scene::Bvh bvh(scene);
  gpu::Renderer renderer;
  gpu::RenderTarget target(160, 96), reference_target(160, 96);
  WalkthroughOptions options;
  options.database = s.store;
  options.error_px = 1e-4;
  Walkthrough walkthrough(scene, gpu_scene, bvh, renderer, options);
  const store::StoreIndex index = store::readIndex(s.store);
  size_t frames = 0;
  for (size_t f = 0; f < s.path.frames.size(); ++f) {
    const Camera camera = s.path.camera(f, 160, 96);
    const FramePlan& plan = walkthrough.plan(camera);
    const store::CellEntry* entry = index.find(plan.report.cell);
    if (!entry) continue;  // not baked: frustum-culled geometry
    ++frames;
    EXPECT_TRUE(plan.report.baked);
    EXPECT_EQ(plan.report.layers_as_geometry, plan.layers.size());
    EXPECT_EQ(plan.report.impostor_triangles, 0u);
    for (const LayerDecision& d : plan.layers) EXPECT_TRUE(std::holds_alternative<LayerAsGeometry>(d));
    // What the plan must show: the cell's near objects and every layered object, as geometry.
    std::vector<uint32_t> ids = entry->pipeline->near;
    for (const store::StoredLayer& layer : entry->pipeline->layers)
      ids.insert(ids.end(), layer.objects.begin(), layer.objects.end());
    std::sort(ids.begin(), ids.end());
    std::vector<gpu::DrawItem> reference;
    gpu_scene.appendDrawItems(ids, reference);
    renderer.render(camera, plan.items, target);
    renderer.render(camera, reference, reference_target);
    EXPECT_EQ(target.readIds().pixels(), reference_target.readIds().pixels()) << "frame " << f;
    EXPECT_EQ(target.readColor().pixels(), reference_target.readColor().pixels()) << "frame " << f;
  }
  EXPECT_GT(frames, 3u);
}

// A plan for a GPU-driven frame (geometry_items false) lists its geometry as objects: drawn by gpu::GpuCuller over
// the scene's arena, then its impostors, every frame equals the frame of the plan's items (geometry culled on the
// CPU), the impostors included; the list's version changes exactly when the list does, and the list only when the
// cell or its layers drawn as geometry do (no frustum query: the GPU culls it).
TEST_F(WalkthroughTest, APlansGeometryObjectsDrawnOnTheGpuEqualItsItems) {
  const BakedCity& s = bakedCity();
  const scene::Scene& scene = s.city.scene;
  const gpu::GpuScene gpu_scene(scene);
  const scene::Bvh bvh(scene);
  const gpu::SceneArena arena(scene);
  gpu::GpuCuller culler(arena);
  gpu::Renderer renderer;
  gpu::RenderTarget target(160, 96), reference_target(160, 96);
  for (const double error_px : {1e-4, 0.0}) {  // every layer as geometry; the bake's bound (impostors)
    WalkthroughOptions options;
    options.database = s.store;
    options.error_px = error_px;
    Walkthrough with_items(scene, gpu_scene, bvh, renderer, options);
    options.geometry_items = false;
    Walkthrough with_objects(scene, gpu_scene, bvh, renderer, options);
    std::vector<uint32_t> last;
    uint64_t version = 0;
    size_t impostor_items = 0, list_changes = 0, key_changes = 0;
    std::pair<uint32_t, std::vector<uint32_t>> last_key{~uint32_t(1), {}};
    for (size_t f = 0; f < s.path.frames.size(); ++f) {
      const Camera camera = s.path.camera(f, 160, 96);
      const FramePlan& a = with_items.plan(camera);
      renderer.render(camera, a.items, reference_target);
      const FramePlan& b = with_objects.plan(camera);
      EXPECT_EQ(b.geometry_items, 0u);
      EXPECT_TRUE(std::is_sorted(b.geometry_objects.begin(), b.geometry_objects.end()));
      EXPECT_EQ(b.geometry_version != version, b.geometry_objects != last) << "frame " << f;
      list_changes += b.geometry_version != version;
      version = b.geometry_version;
      std::pair<uint32_t, std::vector<uint32_t>> key{b.report.cell, {}};
      for (const LayerDecision& d : b.layers)
        if (const auto* g = std::get_if<LayerAsGeometry>(&d)) key.second.push_back(g->layer);
      key_changes += key != last_key;
      last_key = key;
      last = b.geometry_objects;
      // Every object the items draw is listed.
      for (size_t i = 0; i < a.geometry_items; ++i)
        EXPECT_TRUE(std::binary_search(last.begin(), last.end(), a.items[i].object_id)) << "frame " << f;
      ASSERT_EQ(b.items.size(), a.items.size() - a.geometry_items) << "frame " << f;  // the impostors
      impostor_items += b.items.size();
      culler.setObjects(b.geometry_objects);
      target.bind();
      target.clear(renderer.light().sky_color);
      culler.draw(camera, target, gpu::RenderMode::Shaded, renderer.light());
      renderer.draw(camera, b.items, target);
      EXPECT_EQ(target.readIds().pixels(), reference_target.readIds().pixels()) << "frame " << f;
      EXPECT_EQ(target.readColor().pixels(), reference_target.readColor().pixels()) << "frame " << f;
      // Then the same view with a near far plane sees fewer objects in its frustum, and the same cell and layers: the
      // same list (the GPU culls by the frustum), not another.
      Camera shallow = camera;
      shallow.far_plane = 20.0f;
      const uint64_t before = b.geometry_version;
      EXPECT_EQ(with_objects.plan(shallow).geometry_version, before) << "frame " << f;
    }
    if (error_px == 0.0) {
      EXPECT_GT(impostor_items, 0u);
    }
    EXPECT_LE(list_changes, key_changes);
    EXPECT_LT(key_changes, s.path.frames.size());  // not vacuous: frames that keep their cell and layers
    std::printf("%zu frames, %zu list changes, %zu cell or layer changes\n", s.path.frames.size(), list_changes,
                key_changes);
  }
}

TEST_F(WalkthroughTest, UnderTheBakesBoundImpostorsAreDrawnOnlyInsideTheirRegions) {
  const BakedCity& s = bakedCity();
  const scene::Scene& scene = s.city.scene;
  const gpu::GpuScene gpu_scene(scene);
  const scene::Bvh bvh(scene);
  gpu::Renderer renderer;
  WalkthroughOptions options;
  options.database = s.store;
  Walkthrough walkthrough(scene, gpu_scene, bvh, renderer, options);
  EXPECT_EQ(walkthrough.errorBoundPx(), extract::PipelineOptions{}.error_px);  // the database's bound
  size_t impostors = 0;
  for (size_t f = 0; f < s.path.frames.size(); ++f) {
    const Camera camera = s.path.camera(f, 160, 96);
    const FramePlan& plan = walkthrough.plan(camera);
    for (const LayerDecision& d : plan.layers) {
      ASSERT_FALSE(std::holds_alternative<LayerUnchecked>(d));  // a version 3 database has regions
      if (const auto* i = std::get_if<LayerAsImpostor>(&d)) {
        ++impostors;
        EXPECT_LE(i->error_rad, i->bound_rad);
        EXPECT_GE(i->bound_rad, plan.report.bound_rad);  // the frame's corner pixel is the strictest
      }
    }
  }
  EXPECT_GT(impostors, 0u);
  EXPECT_EQ(walkthrough.statistics().at("frames"), double(s.path.frames.size()));
}

// GPU residency under a byte budget, and cells read ahead: with a budget of about one cell, the resident bytes stay
// under it whenever more than the current cell is resident (cells are evicted, least recent first), and every frame
// draws exactly what the same walkthrough draws with an unlimited budget and without reading ahead.
TEST_F(WalkthroughTest, ResidentImpostorsStayUnderTheGpuBudgetAndReadAheadChangesNothing) {
  const BakedCity& s = bakedCity();
  const scene::Scene& scene = s.city.scene;
  const gpu::GpuScene gpu_scene(scene);
  const scene::Bvh bvh(scene);
  gpu::Renderer renderer;
  gpu::RenderTarget target(160, 96), reference_target(160, 96);
  WalkthroughOptions reference_options;
  reference_options.database = s.store;
  reference_options.read_ahead = false;
  Walkthrough reference(scene, gpu_scene, bvh, renderer, reference_options);
  // The largest cell's bytes, from a first walk with everything resident.
  uint64_t largest = 0, previous = 0;
  for (size_t f = 0; f < s.path.frames.size(); ++f) {
    const FramePlan& plan = reference.plan(s.path.camera(f, 160, 96));
    if (plan.report.loaded) largest = std::max(largest, plan.report.resident_bytes - previous);
    previous = plan.report.resident_bytes;
  }
  ASSERT_GT(largest, 0u);
  EXPECT_EQ(reference.statistics().at("cache_evictions"), 0.0);

  WalkthroughOptions tight = reference_options;
  tight.gpu_budget_bytes = largest + largest / 2;
  tight.read_ahead = true;
  Walkthrough budgeted(scene, gpu_scene, bvh, renderer, tight);
  Walkthrough unlimited(scene, gpu_scene, bvh, renderer, reference_options);
  size_t loads = 0;
  for (size_t f = 0; f < s.path.frames.size(); ++f) {
    const Camera camera = s.path.camera(f, 160, 96);
    const FramePlan& plan = budgeted.plan(camera);
    loads += plan.report.loaded ? 1 : 0;
    if (!plan.report.over_gpu_budget) {
      EXPECT_LE(plan.report.resident_bytes, tight.gpu_budget_bytes) << "frame " << f;
    }
    renderer.render(camera, plan.items, target);
    renderer.render(camera, unlimited.plan(camera).items, reference_target);
    EXPECT_EQ(target.readColor().pixels(), reference_target.readColor().pixels()) << "frame " << f;
  }
  const auto stats = budgeted.statistics();
  EXPECT_LE(stats.at("resident_bytes_max"), double(tight.gpu_budget_bytes));
  EXPECT_GT(stats.at("cache_evictions"), 0.0);  // the path visits more cells than the budget holds
  EXPECT_EQ(stats.at("cell_loads"), double(loads));
  EXPECT_EQ(stats.at("cells_entered_ready") + stats.at("cells_entered_waiting") + stats.at("cells_entered_cold"),
            double(loads));
  EXPECT_GT(stats.at("cells_read_ahead"), 0.0);
  // The walk follows the streets: cells after the first were read ahead (finished or not when entered).
  EXPECT_GT(stats.at("cells_entered_ready") + stats.at("cells_entered_waiting"), 0.0);
}

TEST_F(WalkthroughTest, BadOptionsAreErrors) {
  const BakedCity& s = bakedCity();
  const gpu::GpuScene gpu_scene(s.city.scene);
  const scene::Bvh bvh(s.city.scene);
  gpu::Renderer renderer;
  WalkthroughOptions none;
  EXPECT_THROW(Walkthrough(s.city.scene, gpu_scene, bvh, renderer, none), Error);
  WalkthroughOptions missing;
  missing.database = test::scratchDir("walkthrough_missing").string() + "/nothing";
  EXPECT_THROW(Walkthrough(s.city.scene, gpu_scene, bvh, renderer, missing), Error);
  WalkthroughOptions negative;
  negative.database = s.store;
  negative.error_px = -1.0;
  EXPECT_THROW(Walkthrough(s.city.scene, gpu_scene, bvh, renderer, negative), Error);
}

}  // namespace
}  // namespace farfield::runtime
