// The impostor bench modes on a small generated city: a short bake, then a street walk through the benchmark harness
// against full-geometry reference frames; the LRU cache; fallbacks and bad stores.
#include <gtest/gtest.h>

#include <filesystem>
#include <set>

#include "farfield/bake/bake.h"
#include "farfield/core/error.h"
#include "farfield/eval/bench.h"
#include "farfield/eval/frame_runner.h"
#include "farfield/gen/city.h"
#include "farfield/gpu/context.h"
#include "farfield/image/metrics.h"
#include "farfield/eval/impostor_mode.h"
#include "farfield/store/impostor_store.h"
#include "farfield/urban/cells.h"
#include "support/test_support.h"

namespace fs = std::filesystem;

namespace farfield::eval {
namespace {

constexpr int kFrameSize = 192;

// A 16-block city with plain boxes (detail 0), a 20-frame drive through it at 5 m per frame, and the cells it visits
// baked at 256 x 256 with both techniques. Built once for the suite.
struct SmallCity {
  gen::City city;
  gen::CameraPath path;
  std::vector<uint32_t> visited;
  std::string store;           // local model: edge
  std::string junction_store;  // local model: junction
};

const SmallCity& smallCity() {
  static const SmallCity* s = [] {
    auto* c = new SmallCity;
    gen::CityOptions o;
    o.blocks = 16;
    o.detail = 0;
    o.seed = 3;
    c->city = gen::generateCity(o);
    gen::StreetWalkOptions walk;
    walk.frames = 20;
    walk.walker = gen::Walker::Car;
    walk.fps = 2.0f;  // 5 m between frames: a few cells in 20 frames
    walk.seed = 2;
    c->path = gen::streetWalk(c->city.streets, walk);
    const urban::CellMap cells(c->city.streets, c->city.scene);
    c->visited = bake::cellsOnPath(cells, c->path);
    c->store = test::scratchDir("runtime_small_city").string();
    extract::BakeOptions b;
    b.techniques = {extract::kDepthMesh, extract::kGridMesh};
    b.resolution = 256;
    b.progress = false;
    bake::bakeCells(gpu::sharedHeadlessContext(), c->city.scene, cells, c->visited, b, c->store);
    // The same cells with the junction local model (the blocks around both end junctions are geometry too).
    urban::CellOptions junction;
    junction.local = urban::LocalModel::Junction;
    const urban::CellMap junction_cells(c->city.streets, c->city.scene, junction);
    c->junction_store = test::scratchDir("runtime_small_city_junction").string();
    bake::bakeCells(gpu::sharedHeadlessContext(), c->city.scene, junction_cells, c->visited, b, c->junction_store);
    return c;
  }();
  return *s;
}

BenchResult runModes(const SmallCity& s, std::vector<std::string> modes, const std::string& store) {
  registerImpostorModes();
  BenchOptions options;
  options.modes = std::move(modes);
  options.width = options.height = kFrameSize;
  options.reference = true;
  options.samples = 0;
  options.mode_options["impostor_dir"] = store;
  return runBench(gpu::sharedHeadlessContext(), s.city.scene, s.path, options);
}

TEST(ImpostorModeTest, DepthMeshWalkHasBoundedErrorAndDrawsFarFewerTrianglesThanFull) {
  const SmallCity& s = smallCity();
  ASSERT_GE(s.visited.size(), 2u) << "the walk should cross at least one junction";
  const BenchResult r = runModes(s, {"full", "depth-mesh", "grid-mesh"}, s.store);
  const ModeResult* full = r.mode("full");
  const ModeResult* depth = r.mode("depth-mesh");
  const ModeResult* grid = r.mode("grid-mesh");
  ASSERT_TRUE(full && depth && grid);
  ASSERT_EQ(depth->frames.size(), s.path.frames.size());

  // Every frame found its cell baked; each visited cell's impostor was loaded once (the cache holds them all).
  EXPECT_EQ(depth->info.at("fallback_frames"), 0.0);
  EXPECT_EQ(depth->info.at("impostor_loads"), double(s.visited.size()));
  EXPECT_EQ(depth->info.at("cells_visited"), double(s.visited.size()));
  EXPECT_EQ(depth->info.at("baked_cells"), double(s.visited.size()));
  EXPECT_GT(depth->info.at("mean_impostor_triangles"), 0.0);

  // Far fewer triangles than full geometry: the local model (two blocks and the ground) and one impostor.
  EXPECT_LT(depth->mean_triangles, 0.35 * full->mean_triangles)
      << depth->mean_triangles << " vs " << full->mean_triangles;
  EXPECT_LT(grid->mean_triangles, 0.35 * full->mean_triangles);

  // Bounded error against the full-geometry reference. Measured on llvmpipe: PSNR 27.4 dB mean, 17.3 dB min, SSIM
  // 0.93, 7% of pixels over 8/255, 1.5% cracks. The error grows along each street (35 dB at the creation point,
  // section 4.2's exact reproduction, less the 256 px texture magnified into a 60-degree view) and peaks at the end
  // of the street, where the buildings across the next junction belong to the distant model, were captured about
  // 90 m away and are now a few metres from the viewer: their sides were never seen (the paper's cracking "when the
  // user comes very close to the boundary", section 5). The bars leave 2-3 dB of margin; the local model alone
  // scores 15 dB (next test), so an impostor that stopped working fails them.
  EXPECT_GE(depth->psnr_db_mean, 24.0);
  EXPECT_GE(depth->psnr_db_min, 15.5);
  EXPECT_GE(depth->ssim_mean, 0.85);
  EXPECT_LE(depth->bad_pixel_share_mean, 0.15);
  EXPECT_LE(depth->crack_share_mean, 0.03);
  EXPECT_EQ(full->crack_share_mean, 0.0);
  std::printf("small city walk: full %.0f triangles; depth-mesh %.0f triangles, PSNR %.2f (min %.2f) dB, SSIM %.3f, "
              "%.2f%% > 8/255, cracks %.3f%%; grid-mesh PSNR %.2f dB, cracks %.3f%%\n",
              full->mean_triangles, depth->mean_triangles, depth->psnr_db_mean, depth->psnr_db_min, depth->ssim_mean,
              100.0 * depth->bad_pixel_share_mean, 100.0 * depth->crack_share_mean, grid->psnr_db_mean,
              100.0 * grid->crack_share_mean);
}

// The impostor is what keeps the error bounded: the local model alone (the distant city left out) is much worse on the
// same frames. Rendered here directly from the store's local object lists.
TEST(ImpostorModeTest, LocalModelAloneIsMuchWorseThanWithTheImpostor) {
  const SmallCity& s = smallCity();
  const store::StoreIndex index = store::readIndex(s.store);
  const urban::StreetGraph graph = urban::StreetGraph::load((fs::path(s.store) / index.streets).string());
  gpu::sharedHeadlessContext().makeCurrent();
  gpu::GpuScene gpu_scene(s.city.scene);
  gpu::Renderer renderer;
  gpu::RenderTarget target(kFrameSize, kFrameSize);
  double psnr_sum = 0.0;
  for (size_t i = 0; i < s.path.frames.size(); ++i) {
    const Camera camera = pathCamera(s.path, i, kFrameSize, kFrameSize);
    renderer.render(camera, gpu_scene.drawItems(), target);
    const image::ColorImage full = target.readColor();
    const uint32_t cell = graph.nearestOrientedEdge(Vec2(camera.eye), Vec2(camera.at - camera.eye));
    const store::CellEntry* entry = index.find(cell);
    ASSERT_NE(entry, nullptr);
    std::vector<gpu::DrawItem> items;
    gpu_scene.appendDrawItems(entry->local_objects, items);
    renderer.render(camera, items, target);
    psnr_sum += std::min(99.0, image::compareImages(full, target.readColor(), 8).psnr_db);
  }
  const double local_only = psnr_sum / double(s.path.frames.size());
  const BenchResult r = runModes(s, {"depth-mesh"}, s.store);
  const double with_impostor = r.mode("depth-mesh")->psnr_db_mean;
  std::printf("local model alone: PSNR %.2f dB; with the depth-mesh impostor: %.2f dB\n", local_only, with_impostor);
  EXPECT_GT(with_impostor, local_only + 3.0);
}

// The paper's "pointwise connectivity" (section 4.1): with the blocks around both end junctions in the local model,
// the street ends no longer show magnified impostor buildings. Measured: 34.2 dB mean, 26.0 dB min (edge: 27.4, 17.3).
TEST(ImpostorModeTest, JunctionLocalModelReducesTheErrorAtStreetEnds) {
  const SmallCity& s = smallCity();
  const BenchResult edge = runModes(s, {"depth-mesh"}, s.store);
  const BenchResult junction = runModes(s, {"depth-mesh"}, s.junction_store);
  const ModeResult* e = edge.mode("depth-mesh");
  const ModeResult* j = junction.mode("depth-mesh");
  std::printf("depth-mesh, local model edge: PSNR %.2f (min %.2f) dB, %.0f triangles; junction: %.2f (min %.2f) dB, "
              "%.0f triangles\n",
              e->psnr_db_mean, e->psnr_db_min, e->mean_triangles, j->psnr_db_mean, j->psnr_db_min, j->mean_triangles);
  EXPECT_GT(j->psnr_db_min, e->psnr_db_min + 4.0);
  EXPECT_GT(j->psnr_db_mean, e->psnr_db_mean + 3.0);
  EXPECT_GT(j->mean_triangles, e->mean_triangles);  // the price: more local geometry
}

TEST(ImpostorModeTest, CellsWithoutImpostorFallBackToCulledGeometry) {
  const SmallCity& s = smallCity();
  // A store with the first visited cell only.
  const std::string dir = test::scratchDir("runtime_one_cell").string();
  const urban::CellMap cells(s.city.streets, s.city.scene);
  extract::BakeOptions b;
  b.techniques = {extract::kDepthMesh};
  b.resolution = 64;
  b.progress = false;
  bake::bakeCells(gpu::sharedHeadlessContext(), s.city.scene, cells, {s.visited.front()}, b, dir);
  size_t expected_fallbacks = 0;
  for (const gen::PathFrame& f : s.path.frames)
    expected_fallbacks += cells.lookup(f.eye, f.at - f.eye) != s.visited.front() ? 1 : 0;
  ASSERT_GT(expected_fallbacks, 0u);

  const BenchResult r = runModes(s, {"culled", "depth-mesh"}, dir);
  const ModeResult* depth = r.mode("depth-mesh");
  const ModeResult* culled = r.mode("culled");
  EXPECT_EQ(depth->info.at("fallback_frames"), double(expected_fallbacks));
  EXPECT_EQ(depth->info.at("impostor_loads"), 1.0);
  // Fallback frames are the culled mode's frames: identical images and triangle counts.
  for (size_t k = 0; k < depth->frames.size(); ++k) {
    const gen::PathFrame& f = s.path.frames[depth->frames[k].path_frame];
    if (cells.lookup(f.eye, f.at - f.eye) == s.visited.front()) continue;
    EXPECT_EQ(depth->frames[k].triangles, culled->frames[k].triangles) << "frame " << k;
    EXPECT_EQ(depth->errors[k].psnr_db, culled->errors[k].psnr_db) << "frame " << k;
  }
}

TEST(ImpostorModeTest, BadStoresAreErrors) {
  const SmallCity& s = smallCity();
  registerImpostorModes();
  ModeContext context;
  context.scene = &s.city.scene;
  EXPECT_THROW(createMode("depth-mesh", context), Error);  // no impostor_dir
  context.options["impostor_dir"] = s.store;
  context.options["impostor_cache"] = "zero";
  EXPECT_THROW(createMode("depth-mesh", context), Error);
  context.options.erase("impostor_cache");
  context.options["impostor_dir"] = (fs::path(s.store) / "missing").string();
  auto mode = createMode("depth-mesh", context);
  EXPECT_THROW(mode->prepare(context), Error);

  // A store of the depth mesh only has no grid-mesh impostors.
  const std::string dir = test::scratchDir("runtime_depth_only").string();
  const urban::CellMap cells(s.city.streets, s.city.scene);
  extract::BakeOptions b;
  b.resolution = 32;
  b.progress = false;
  bake::bakeCells(gpu::sharedHeadlessContext(), s.city.scene, cells, {s.visited.front()}, b, dir);
  context.options["impostor_dir"] = dir;
  try {
    createMode("grid-mesh", context)->prepare(context);
    ADD_FAILURE() << "expected farfield::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no grid-mesh impostors"), std::string::npos) << e.what();
  }
  // A scene other than the one baked.
  scene::Scene other = s.city.scene;
  other.objects.pop_back();
  context.scene = &other;
  context.options["impostor_dir"] = s.store;
  try {
    createMode("depth-mesh", context)->prepare(context);
    ADD_FAILURE() << "expected farfield::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("baked for a scene with"), std::string::npos) << e.what();
  }
  // A per-technique directory overrides impostor_dir.
  context.scene = &s.city.scene;
  context.options["impostor_dir"] = "/nonexistent";
  context.options["depth_mesh_dir"] = s.store;
  EXPECT_NO_THROW(createMode("depth-mesh", context)->prepare(context));
}

TEST(ImpostorCacheTest, EvictsTheLeastRecentlyUsed) {
  std::vector<uint32_t> loaded;
  ImpostorCache cache(2, [&](uint32_t cell) {
    loaded.push_back(cell);
    return std::make_unique<impostor::GpuImpostor>(impostor::DepthMeshImpostor{});  // empty: no GL objects
  });
  for (uint32_t cell : {1u, 2u, 1u, 3u, 1u, 2u, 2u}) cache.get(cell);
  // 1, 2 loaded; 1 hit; 3 evicts 2 (least recent); 1 hit; 2 evicts 3.
  EXPECT_EQ(loaded, (std::vector<uint32_t>{1, 2, 3, 2}));
  EXPECT_EQ(cache.loads(), 4u);
  EXPECT_EQ(cache.evictions(), 2u);
  EXPECT_TRUE(cache.contains(1));
  EXPECT_TRUE(cache.contains(2));
  EXPECT_FALSE(cache.contains(3));
}

}  // namespace
}  // namespace farfield::eval
