// Sillion's bake, which is the pipeline near-far,single with one station per cell (`farfield bake --technique`):
// creation cameras, empty distant models, degenerate streets, determinism across worker counts, cells on a path,
// ground height; and the baked impostor plus the local model reproduce the full render from the creation viewpoint,
// where its validity region lets the runtime draw it.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>

#include "farfield/bake/bake.h"
#include "farfield/bake/pipeline.h"
#include "farfield/extract/ground_height.h"
#include "farfield/core/error.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/renderer.h"
#include "farfield/image/metrics.h"
#include "farfield/impostor/drawable.h"
#include "farfield/scene/builtin.h"
#include "farfield/store/impostor_store.h"
#include "support/test_support.h"

namespace farfield::bake {
using namespace farfield::extract;
namespace {

using urban::CellMap;
using urban::Street;
using urban::StreetGraph;

// Two 60 m blocks side by side (x in [0, 120], y in [0, 60]) and a 5 mm dead end at (120, 0):
//   junctions 0 (0,0) 1 (60,0) 2 (120,0) 3 (0,60) 4 (60,60) 5 (120,60) 6 (120.005, 0)
//   streets 0: 0-1, 1: 1-2, 2: 3-4, 3: 4-5, 4: 0-3, 5: 1-4 (between the blocks), 6: 2-5, 7: 2-6 (degenerate)
// Objects: 1 ground (shared), 2 a 20 m box in the left block, 3 a 40 m tower in the right block.
struct TwoBlocks {
  StreetGraph graph;
  scene::Scene scene;
};

TwoBlocks twoBlocks() {
  TwoBlocks t;
  t.graph = StreetGraph::build({{0, 0}, {60, 0}, {120, 0}, {0, 60}, {60, 60}, {120, 60}, {120.005f, 0}},
                               {{0, 1}, {1, 2}, {3, 4}, {4, 5}, {0, 3}, {1, 4}, {2, 5}, {2, 6}}, "two blocks");
  auto add = [&](scene::Mesh mesh, const Vec4& color, std::vector<Vec2> footprint) {
    scene::Material m;
    m.base_color = color;
    scene::Object o;
    o.parts.push_back({t.scene.addMesh(std::move(mesh)), t.scene.addMaterial(m)});
    o.footprint = std::move(footprint);
    t.scene.addObject(o);
  };
  add(scene::makeGroundQuad(Vec2(-100.0f), Vec2(220.0f, 160.0f)), Vec4(0.5f, 0.55f, 0.45f, 1.0f),
      {{-100, -100}, {220, -100}, {220, 160}, {-100, 160}});
  add(scene::makeBox(Vec3(15, 15, 0), Vec3(45, 45, 20)), Vec4(0.9f, 0.5f, 0.3f, 1.0f),
      {{15, 15}, {45, 15}, {45, 45}, {15, 45}});
  add(scene::makeBox(Vec3(75, 15, 0), Vec3(105, 45, 40)), Vec4(0.3f, 0.4f, 0.9f, 1.0f),
      {{75, 15}, {105, 15}, {105, 45}, {75, 45}});
  return t;
}

// Sillion's bake as it is now: the pipeline near-far,single with one capture station at each cell's start
// (`farfield bake --technique depth-mesh|grid-mesh`).
PipelineOptions sillionOptions(LayerMesh mesh = LayerMesh::DepthMesh) {
  PipelineOptions o;
  o.base.resolution = 128;
  o.base.progress = false;
  o.mesh = mesh;
  o.station_spacing = 0.0f;
  return o;
}

PipelineReport bakeSillion(const scene::Scene& scene, const CellMap& cells, std::vector<uint32_t> half_edges,
                           const PipelineOptions& options, const std::string& dir) {
  return bakePipeline(gpu::sharedHeadlessContext(), scene, cells, std::move(half_edges),
                      parsePipeline(kTechniquePipeline), options, dir);
}

// The one view of a cell's single mesh (one station, the street view).
const store::StoredView& onlyView(const store::CellEntry& entry) {
  EXPECT_TRUE(entry.pipeline && entry.pipeline->has_single);
  EXPECT_EQ(entry.pipeline->single.views.size(), 1u);
  return entry.pipeline->single.views.at(0);
}

class BakeGpuTest : public ::testing::Test {
 protected:
  void SetUp() override { gpu::sharedHeadlessContext(); }
};

TEST_F(BakeGpuTest, EmptyDistantModelGivesEmptyImpostorAndDegenerateStreetIsReported) {
  const TwoBlocks t = twoBlocks();
  const CellMap cells(t.graph, t.scene);
  const std::string dir = test::scratchDir("bake_two_blocks").string();
  const PipelineReport report = bakeSillion(t.scene, cells, {}, sillionOptions(), dir);
  EXPECT_EQ(report.requested, 16u);
  EXPECT_EQ(report.skipped_degenerate, (std::vector<uint32_t>{14, 15}));
  ASSERT_EQ(report.cells.size(), 14u);

  const store::StoreIndex index = store::readIndex(dir);
  ASSERT_EQ(index.cells.size(), 14u);
  EXPECT_EQ(index.pipeline, (std::vector<std::string>{"near-far", "single"}));
  EXPECT_TRUE(index.techniques.empty());  // no Sillion record kind: the single stage's record
  EXPECT_EQ(index.find(14), nullptr);
  EXPECT_EQ(index.scene_objects, 3u);
  for (const store::CellEntry& e : index.cells) {
    ASSERT_TRUE(e.pipeline);
    EXPECT_FALSE(e.pipeline->has_mmi);
    EXPECT_FALSE(e.pipeline->has_pvs);
  }
  // Street 5 lies between the two blocks: its local model is everything, its distant model nothing.
  for (uint32_t e : {10u, 11u}) {
    const store::CellEntry* entry = index.find(e);
    ASSERT_NE(entry, nullptr);
    EXPECT_EQ(entry->local_objects, (std::vector<uint32_t>{1, 2, 3}));
    EXPECT_EQ(entry->pipeline->near, (std::vector<uint32_t>{1, 2, 3}));
    EXPECT_TRUE(entry->pipeline->far.empty());
    EXPECT_TRUE(entry->pipeline->single.objects.empty());
    const store::StoredView& view = onlyView(*entry);
    EXPECT_EQ(view.triangles, 0u);
    EXPECT_EQ(view.data_pixels, 0u);
    EXPECT_TRUE(store::loadLayerView(dir, view).empty());
  }
  // Street 0 (0,0) -> (60,0) borders the left block only: the tower is its distant model, seen ahead on the left.
  const store::CellEntry* e0 = index.find(0);
  ASSERT_NE(e0, nullptr);
  EXPECT_EQ(e0->local_objects, (std::vector<uint32_t>{1, 2}));
  EXPECT_EQ(e0->pipeline->near, (std::vector<uint32_t>{1, 2}));
  EXPECT_EQ(e0->pipeline->far, (std::vector<uint32_t>{3}));
  EXPECT_EQ(e0->pipeline->single.objects, (std::vector<uint32_t>{3}));
  const store::StoredView& v0 = onlyView(*e0);
  EXPECT_GT(v0.data_pixels, 100u);
  EXPECT_GT(v0.triangles, 0u);
  // Its creation camera: at the edge origin, 1.7 m above the flat ground, looking at the edge end; one station
  // (the paper's one capture per cell) with its validity region there.
  EXPECT_NEAR(glm::length(v0.camera.eye - Vec3(0, 0, 1.7f)), 0.0f, 1e-4f);
  EXPECT_NEAR(glm::length(v0.camera.at - Vec3(60, 0, 1.7f)), 0.0f, 1e-4f);
  EXPECT_NEAR(v0.camera.fov_y, float(degToRad(60.0)), 1e-6f);
  EXPECT_EQ(v0.camera.width, 128);
  EXPECT_EQ(v0.station, 0u);
  ASSERT_EQ(e0->pipeline->single.validity.size(), 1u);
  EXPECT_EQ(e0->pipeline->single.validity[0].origin, v0.camera.eye);
  EXPECT_EQ(e0->camera.eye, v0.camera.eye);
  // The mesh kind is recorded with the options (the bench's depth-mesh mode checks it).
  EXPECT_EQ(pipelineOptionsFromJson(index.options.at("pipeline"), "index").mesh, LayerMesh::DepthMesh);
  EXPECT_EQ(pipelineOptionsFromJson(index.options.at("pipeline"), "index").station_spacing, 0.0f);
  // A copy of the street graph travels with the store.
  EXPECT_EQ(StreetGraph::load((std::filesystem::path(dir) / index.streets).string()).streetCount(), 8u);
}

TEST_F(BakeGpuTest, ImpostorPlusLocalModelReproducesTheFullRenderFromTheCreationViewpoint) {
  const TwoBlocks t = twoBlocks();
  const CellMap cells(t.graph, t.scene);
  for (const LayerMesh mesh : {LayerMesh::DepthMesh, LayerMesh::Grid}) {
    SCOPED_TRACE(layerMeshName(mesh));
    const std::string dir = test::scratchDir(std::string("bake_creation_view_") + layerMeshName(mesh)).string();
    PipelineOptions options = sillionOptions(mesh);
    options.base.resolution = 256;
    options.base.fov_deg = 60.0f;
    const PipelineReport report = bakeSillion(t.scene, cells, {0, 1, 4}, options, dir);
    const store::StoreIndex index = store::readIndex(dir);
    ASSERT_EQ(index.cells.size(), 3u);

    gpu::GpuScene gpu_scene(t.scene);
    gpu::Renderer renderer;
    gpu::RenderTarget target(256, 256);
    for (const store::CellEntry& entry : index.cells) {
      const store::StoredView& view = onlyView(entry);
      const Camera& camera = view.camera;
      renderer.render(camera, gpu_scene.drawItems(), target);
      const image::ColorImage full = target.readColor();
      const impostor::GpuImpostor imp(store::loadLayerView(dir, view));
      std::vector<gpu::DrawItem> items;
      gpu_scene.appendDrawItems(entry.pipeline->near, items);
      imp.appendDrawItems(items, 99);
      renderer.render(camera, items, target);
      const image::ColorImage composed = target.readColor();
      const image::ImageMetrics m = image::compareImages(full, composed, 8);
      // The bar for an impostor seen from its creation viewpoint.
      EXPECT_GE(m.psnr_db, mesh == LayerMesh::DepthMesh ? 35.0 : 30.0) << "cell " << entry.half_edge;
      EXPECT_LE(m.bad_pixel_share, 0.01) << "cell " << entry.half_edge;
      // And the runtime may draw it there: at its creation eye the validity region is within the bake's bound.
      const impostor::ValidityRegion& region = entry.pipeline->single.validity.at(0);
      EXPECT_TRUE(region.valid(camera.eye, report.threshold_rad)) << "cell " << entry.half_edge;
    }
    // Without the impostor, cell 0 loses the tower: the check above can fail.
    const store::CellEntry& e0 = *index.find(0);
    const Camera& c0 = onlyView(e0).camera;
    renderer.render(c0, gpu_scene.drawItems(), target);
    const image::ColorImage full = target.readColor();
    std::vector<gpu::DrawItem> local;
    gpu_scene.appendDrawItems(e0.pipeline->near, local);
    renderer.render(c0, local, target);
    EXPECT_LT(image::compareImages(full, target.readColor(), 8).psnr_db, 30.0);
  }
}

TEST_F(BakeGpuTest, ResultDoesNotDependOnTheNumberOfWorkers) {
  const TwoBlocks t = twoBlocks();
  const CellMap cells(t.graph, t.scene);
  PipelineOptions options = sillionOptions();
  options.base.resolution = 64;
  options.base.workers = 1;
  const std::string one_dir = test::scratchDir("bake_w1").string(), three_dir = test::scratchDir("bake_w3").string();
  bakeSillion(t.scene, cells, {}, options, one_dir);
  options.base.workers = 3;
  options.base.queue_capacity = 1;
  const PipelineReport three = bakeSillion(t.scene, cells, {}, options, three_dir);
  EXPECT_EQ(three.workers, 3u);
  const store::StoreIndex a = store::readIndex(one_dir);
  const store::StoreIndex b = store::readIndex(three_dir);
  ASSERT_EQ(a.cells.size(), b.cells.size());
  size_t with_triangles = 0;
  for (size_t i = 0; i < a.cells.size(); ++i) {
    EXPECT_EQ(a.cells[i].half_edge, b.cells[i].half_edge);
    EXPECT_EQ(onlyView(a.cells[i]).triangles, onlyView(b.cells[i]).triangles) << "cell " << a.cells[i].half_edge;
    EXPECT_EQ(a.cells[i].pipeline->single.validity.at(0).envelope, b.cells[i].pipeline->single.validity.at(0).envelope);
    with_triangles += onlyView(a.cells[i]).triangles > 0 ? 1 : 0;
  }
  EXPECT_GT(with_triangles, 0u);
}

TEST_F(BakeGpuTest, BadRequestsAreErrors) {
  const TwoBlocks t = twoBlocks();
  const CellMap cells(t.graph, t.scene);
  const std::string dir = test::scratchDir("bake_bad").string();
  EXPECT_THROW(bakeSillion(t.scene, cells, {99}, sillionOptions(), dir), Error);
  PipelineOptions options = sillionOptions();
  options.base.fov_deg = 180.0f;
  EXPECT_THROW(bakeSillion(t.scene, cells, {0}, options, dir), Error);
  EXPECT_THROW(techniqueMesh("billboard"), Error);
  EXPECT_THROW(techniqueMesh("both"), Error);
  // A cell map of another scene.
  scene::Scene other;
  EXPECT_THROW(bakeSillion(other, cells, {0}, sillionOptions(), dir), Error);
}

TEST(BakeTest, CellsOnPathInOrderOfFirstVisit) {
  const TwoBlocks t = twoBlocks();
  const CellMap cells(t.graph, t.scene);
  gen::CameraPath path;
  // Along the bottom street eastwards, then back westwards.
  for (int i = 0; i <= 10; ++i) path.frames.push_back({Vec3(5.0f + 11.0f * float(i), 1.0f, 1.7f),
                                                       Vec3(6.0f + 11.0f * float(i), 1.0f, 1.7f)});
  path.frames.push_back({Vec3(100.0f, -1.0f, 1.7f), Vec3(90.0f, -1.0f, 1.7f)});
  // Street 0 runs 0 -> 1 (half-edge 0 eastwards), street 1 runs 1 -> 2 (half-edge 2 eastwards, 3 westwards).
  EXPECT_EQ(cellsOnPath(cells, path), (std::vector<uint32_t>{0, 2, 3}));
}

TEST(BakeTest, GroundHeightIsTheLowestUpwardSurfaceUnderThePoint) {
  // A sloped plane z = 0.1 x + 0.05 y + 3 over [0, 100]^2 as a 10 x 10 grid, a vertical wall, and a deck at z = 30
  // over part of it.
  scene::Scene s;
  scene::Mesh ground;
  auto plane = [](float x, float y) { return 0.1f * x + 0.05f * y + 3.0f; };
  for (int j = 0; j <= 10; ++j)
    for (int i = 0; i <= 10; ++i) ground.positions.emplace_back(10.0f * i, 10.0f * j, plane(10.0f * i, 10.0f * j));
  for (int j = 0; j < 10; ++j)
    for (int i = 0; i < 10; ++i) {
      const uint32_t a = uint32_t(j * 11 + i), b = a + 1, c = a + 11, d = a + 12;
      ground.indices.insert(ground.indices.end(), {a, b, d, a, d, c});
    }
  scene::Mesh wall;
  wall.positions = {{50, 0, 0}, {50, 100, 0}, {50, 100, 200}};
  wall.indices = {0, 1, 2};
  scene::Mesh deck = scene::makeGroundQuad(Vec2(20.0f), Vec2(40.0f));
  for (Vec3& p : deck.positions) p.z = 30.0f;
  for (scene::Mesh* m : {&ground, &wall, &deck}) {
    scene::Object o;
    o.parts.push_back({s.addMesh(*m), 0});
    s.addObject(o);
  }
  const std::vector<uint32_t> ids{1, 2, 3};
  const GroundHeight height(s, ids);
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u(0.0f, 100.0f);
  for (int k = 0; k < 200; ++k) {
    const float x = u(rng), y = u(rng);
    EXPECT_NEAR(height.at(x, y, -1.0f), plane(x, y), 1e-3f) << x << ", " << y;
  }
  EXPECT_EQ(height.at(150.0f, 50.0f, -7.0f), -7.0f);  // outside: the fallback
}

}  // namespace
}  // namespace farfield::bake
