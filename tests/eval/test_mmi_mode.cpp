// The pipeline-store bench modes (Decoret et al. 1999, section 6.1 and 5.5): local, visible, smi, mmi and mmi-dynamic
// on a small baked city through the benchmark harness against full-geometry reference frames; dynamic updates of a
// viewer standing still; the fall back to pre-computed layers under fast motion; a store finished online; bad stores
// and options.
#include <gtest/gtest.h>

#include <cmath>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <variant>

#include "farfield/bake/bake.h"
#include "farfield/bake/pipeline.h"
#include "farfield/core/error.h"
#include "farfield/eval/bench.h"
#include "farfield/eval/frame_runner.h"
#include "farfield/gen/city.h"
#include "farfield/gpu/context.h"
#include "farfield/eval/impostor_mode.h"
#include "farfield/eval/mmi_mode.h"
#include "farfield/store/impostor_store.h"
#include "farfield/urban/cells.h"
#include "farfield/gpu/renderer.h"
#include "support/test_support.h"

namespace fs = std::filesystem;

namespace farfield::eval {
namespace {

constexpr int kFrameSize = 192;

// A 16-block city of plain boxes, a 12-frame drive at 5 m per frame, and the cells it visits baked with the full
// pipeline (256 x 256 layer images), once with every stage baked and once with the single and mmi stages left
// online.
struct MmiCity {
  gen::City city;
  std::unique_ptr<urban::CellMap> cells;
  gen::CameraPath path;
  std::vector<uint32_t> visited;
  std::string store, online_store;
};

extract::PipelineOptions pipelineOptions() {
  extract::PipelineOptions o;
  o.base.resolution = 256;
  o.base.progress = false;
  o.pvs.spacing = 8.0f;
  o.pvs.face_size = 64;
  return o;
}

const MmiCity& mmiCity() {
  static const MmiCity* s = [] {
    auto* c = new MmiCity;
    gen::CityOptions o;
    o.blocks = 16;
    o.detail = 0;
    o.seed = 3;
    c->city = gen::generateCity(o);
    c->cells = std::make_unique<urban::CellMap>(c->city.streets, c->city.scene);
    gen::StreetWalkOptions walk;
    walk.frames = 12;
    walk.walker = gen::Walker::Car;
    walk.fps = 2.0f;  // 5 m between frames
    walk.seed = 2;
    c->path = gen::streetWalk(c->city.streets, walk);
    c->visited = bake::cellsOnPath(*c->cells, c->path);
    c->store = test::scratchDir("mmi_mode_store").string();
    bake::bakePipeline(gpu::sharedHeadlessContext(), c->city.scene, *c->cells, c->visited,
                       extract::parsePipeline("pvs,near-far,single,mmi"), pipelineOptions(), c->store);
    c->online_store = test::scratchDir("mmi_mode_online_store").string();
    bake::bakePipeline(gpu::sharedHeadlessContext(), c->city.scene, *c->cells, c->visited,
                       extract::parsePipeline("pvs,near-far,single,mmi", "single,mmi"), pipelineOptions(),
                       c->online_store);
    return c;
  }();
  return *s;
}

BenchResult runModes(const gen::CameraPath& path, std::vector<std::string> modes, const std::string& store,
                           std::map<std::string, std::string> extra = {}) {
  registerImpostorModes();
  BenchOptions options;
  options.modes = std::move(modes);
  options.width = options.height = kFrameSize;
  options.reference = true;
  options.samples = 0;
  options.mode_options = std::move(extra);
  options.mode_options["impostor_dir"] = store;
  return runBench(gpu::sharedHeadlessContext(), mmiCity().city.scene, path, options);
}

class MmiModeTest : public ::testing::Test {
 protected:
  void SetUp() override { gpu::sharedHeadlessContext(); }
};

TEST_F(MmiModeTest, TheFiveModesRunOverTheBakedWalk) {
  const MmiCity& s = mmiCity();
  ASSERT_GE(s.visited.size(), 2u) << "the walk should cross at least one junction";
  const BenchResult r = runModes(s.path, {"frustum", "local", "visible", "smi", "mmi", "mmi-dynamic"}, s.store);
  const ModeResult* full = r.mode("full");
  const ModeResult* culled = r.mode("frustum");  // the runtime's geometry is frustum-culled
  const ModeResult* local = r.mode("local");
  const ModeResult* visible = r.mode("visible");
  const ModeResult* smi = r.mode("smi");
  const ModeResult* mmi = r.mode("mmi");
  const ModeResult* dynamic = r.mode("mmi-dynamic");
  ASSERT_TRUE(full && culled && local && visible && smi && mmi && dynamic);
  ASSERT_EQ(mmi->frames.size(), s.path.frames.size());

  // Every frame found its cell baked; each cell was read once.
  for (const ModeResult* m : {local, visible, smi, mmi, dynamic}) {
    EXPECT_EQ(m->info.at("fallback_frames"), 0.0) << m->name;
    EXPECT_EQ(m->info.at("cells_visited"), double(s.visited.size())) << m->name;
    EXPECT_EQ(m->info.at("cell_loads"), double(s.visited.size())) << m->name;
    EXPECT_EQ(m->info.at("online_runs"), 0.0) << m->name;
  }
  EXPECT_GT(mmi->info.at("mean_layers"), 0.0);
  EXPECT_GT(mmi->info.at("mean_impostor_triangles"), 0.0);
  EXPECT_DOUBLE_EQ(smi->info.at("mean_layers"), 1.0);

  // visible: the PVS, frustum-culled. Where the PVS is complete it renders what full geometry renders.
  EXPECT_GT(visible->psnr_db_mean, 35.0);
  EXPECT_LT(visible->crack_share_mean, 0.002);
  // It draws no more than frustum culling alone in any frame, and far less than full geometry.
  for (size_t k = 0; k < visible->frames.size(); ++k)
    EXPECT_LE(visible->frames[k].triangles, culled->frames[k].triangles) << "frame " << k;
  EXPECT_LT(visible->mean_triangles, full->mean_triangles);
  // local: the near geometry only, less than the PVS; without the far geometry its frames are much worse.
  EXPECT_LT(local->mean_triangles, visible->mean_triangles);
  for (size_t k = 0; k < local->frames.size(); ++k)
    EXPECT_LE(local->frames[k].triangles, visible->frames[k].triangles) << "frame " << k;
  // The impostors put the far geometry back: better than the near geometry alone.
  EXPECT_GT(mmi->psnr_db_mean, local->psnr_db_mean + 2.0);
  EXPECT_GT(smi->psnr_db_mean, local->psnr_db_mean + 2.0);
  EXPECT_LT(mmi->crack_share_mean, local->crack_share_mean);
  // Dynamic layers are rendered from the viewer's eye: they must not add cracks to the precomputed layers' (on this
  // walk only the warm-up frame and frame 0 are slow enough for updates; the rest are mmi's frames).
  EXPECT_LE(dynamic->crack_share_mean, mmi->crack_share_mean + 0.001);

  std::printf("walk (%zu frames, %zu cells): triangles full %.0f, culled %.0f, visible %.0f, local %.0f, smi %.0f, "
              "mmi %.0f, mmi-dynamic %.0f\n",
              mmi->frames.size(), s.visited.size(), full->mean_triangles, culled->mean_triangles,
              visible->mean_triangles, local->mean_triangles, smi->mean_triangles, mmi->mean_triangles,
              dynamic->mean_triangles);
  for (const ModeResult* m : {culled, visible, local, smi, mmi, dynamic})
    std::printf("  %-12s PSNR %6.2f dB (min %6.2f), SSIM %.3f, cracks %.3f%%, median %.2f ms\n", m->name.c_str(),
                m->psnr_db_mean, m->psnr_db_min, m->ssim_mean, 100.0 * m->crack_share_mean, m->wall.median);
  std::printf("  mmi-dynamic: updates %.0f, fast-motion frames %.0f, skipped for budget %.0f\n",
              dynamic->info.at("updates"), dynamic->info.at("fast_motion_frames"),
              dynamic->info.at("updates_skipped_for_budget"));
}

// A camera path that stands at `eye` looking along `dir` for `frames` frames.
void standAt(gen::CameraPath& path, const Vec3& eye, const Vec3& dir, int frames) {
  for (int i = 0; i < frames; ++i) {
    gen::PathFrame f;
    f.eye = eye;
    f.at = eye + 10.0f * glm::normalize(dir);
    path.frames.push_back(f);
  }
}

// The baked cell with the most layers.
uint32_t cellWithMostLayers(const store::StoreIndex& index, size_t* layers) {
  uint32_t best = urban::kNone;
  *layers = 0;
  for (const store::CellEntry& e : index.cells)
    if (e.pipeline && e.pipeline->layers.size() > *layers) {
      *layers = e.pipeline->layers.size();
      best = e.half_edge;
    }
  return best;
}

// Section 5.5: standing still, one layer is refreshed per frame (dynamic_max_updates=1) from the viewer's own eye, so
// the image approaches the reference frame by frame.
//
// The harness renders one untimed warm-up frame at the path's first frame, which already runs the mode's dynamic
// updates. So the path starts 10% along the street (the warm-up and frame 0 update layers there), then jumps to 70%
// along it and stays: the jump is fast motion, so frame 1 drops every dynamic layer and shows the pre-computed MMI
// alone; from frame 2 on, one layer per frame is re-rendered.
TEST_F(MmiModeTest, StandingStillTheDynamicImpostorsReplaceInvalidLayersWithinTheBound) {
  const MmiCity& s = mmiCity();
  const store::StoreIndex index = store::readIndex(s.store);
  size_t layers = 0;
  const uint32_t cell = cellWithMostLayers(index, &layers);
  ASSERT_NE(cell, urban::kNone);
  ASSERT_GE(layers, 2u) << "the test needs a cell with two layers or more";
  const Vec2 p = s.cells->graph().originPosition(cell), q = s.cells->graph().destinationPosition(cell);
  const Vec3 dir(q - p, 0.0f);
  const Vec3 start(p + 0.1f * (q - p), 1.7f), still(p + 0.7f * (q - p), 1.7f);
  gen::CameraPath path;
  path.kind = "standing still";
  standAt(path, start, dir, 1);
  standAt(path, still, dir, 8);
  ASSERT_EQ(s.cells->lookup(start, dir), cell);
  ASSERT_EQ(s.cells->lookup(still, dir), cell);

  const BenchResult r =
      runModes(path, {"mmi", "mmi-dynamic"}, s.store,
               {{"frame_budget_ms", "10000"}, {"dynamic_max_updates", "1"}});
  const ModeResult* mmi = r.mode("mmi");
  const ModeResult* dynamic = r.mode("mmi-dynamic");
  ASSERT_TRUE(mmi && dynamic);
  ASSERT_EQ(dynamic->errors.size(), 9u);
  std::printf("cell %u (%zu layers), standing at 70%%: mmi %.2f dB; mmi-dynamic per frame:", cell, layers,
              mmi->errors.back().psnr_db);
  for (const image::ImageMetrics& e : dynamic->errors) std::printf(" %.2f", e.psnr_db);
  std::printf(" dB; cracks per frame (%%):");
  for (double c : dynamic->crack_shares) std::printf(" %.2f", 100.0 * c);
  std::printf("; updates %.0f, fast-motion frames %.0f, skipped %.0f\n", dynamic->info.at("updates"),
              dynamic->info.at("fast_motion_frames"), dynamic->info.at("updates_skipped_for_budget"));

  EXPECT_EQ(dynamic->info.at("fallback_frames"), 0.0);
  EXPECT_GE(dynamic->info.at("fast_motion_frames"), 1.0);  // the jump
  EXPECT_EQ(dynamic->info.at("updates_skipped_for_budget"), 0.0);
  // Frame 1 (after the jump) is the mmi mode's frame: every dynamic impostor is dropped and each layer is drawn as
  // its baked views where their validity region holds the eye, as geometry elsewhere.
  EXPECT_EQ(dynamic->errors[1].psnr_db, mmi->errors[1].psnr_db);
  EXPECT_EQ(dynamic->frames[1].triangles, mmi->frames[1].triangles);
  // Then layers are re-rendered from the viewer's own eye, one per frame: fresh images, close to the reference, with
  // their parallax under the bound (the mmi mode keeps it with geometry where its layers are not valid).
  const double bound = dynamic->info.at("error_bound_px");
  for (size_t k = 2; k < dynamic->errors.size(); ++k) {
    EXPECT_GE(dynamic->errors[k].psnr_db, 40.0) << "frame " << k;
    if (k < dynamic->parallax_px.size() && !std::isnan(dynamic->parallax_px[k])) {
      EXPECT_LE(dynamic->parallax_px[k], bound) << "frame " << k;
    }
    if (k < mmi->parallax_px.size() && !std::isnan(mmi->parallax_px[k])) {
      EXPECT_LE(mmi->parallax_px[k], bound) << "frame " << k;
    }
  }
  EXPECT_GT(dynamic->info.at("mean_dynamic_layers"), 0.0);
  // Rendered from the viewer's own eye, the refreshed layers open no cracks (pixels where the reference shows geometry
  // and the frame's id buffer shows sky).
  // (This caught dynamic layers drawn with object id 0, the sky's, in item buffers: 21-24% cracks at 60 dB.)
  EXPECT_LE(dynamic->crack_shares.back(), mmi->crack_shares.back() + 0.002);
  // At least one update per frame from frame 2 until every layer is fresh: min(layers, 7) after the jump.
  EXPECT_GE(dynamic->info.at("updates"), double(std::min<size_t>(layers, 7)));
}

// Fast motion (section 5.5): at 5 m per frame a fresh impostor would be stale within dynamic_min_lifetime frames, so
// every layer falls back to its pre-computed MMI and nothing is updated: such frames are the mmi mode's frames.
TEST_F(MmiModeTest, FastMotionFallsBackToThePrecomputedLayers) {
  const MmiCity& s = mmiCity();
  // Geometry culled on the CPU: its triangle counts do not depend on the frames a mode drew before (the GPU's
  // two-phase occlusion draws what the last frame saw first).
  const BenchResult r =
      runModes(s.path, {"mmi", "mmi-dynamic"}, s.store, {{"frame_budget_ms", "10000"}, {"geometry", "cpu"}});
  const ModeResult* mmi = r.mode("mmi");
  const ModeResult* dynamic = r.mode("mmi-dynamic");
  ASSERT_TRUE(mmi && dynamic);
  const double fast = dynamic->info.at("fast_motion_frames");
  const double updates = dynamic->info.at("updates");
  std::printf("fast walk: %zu frames, %.0f fast-motion frames, %.0f updates\n", dynamic->frames.size(), fast, updates);
  EXPECT_GT(fast, 0.0);
  // Every cell of the walk has layers, so every frame after the first is judged, and each is 5 m from the last.
  EXPECT_EQ(fast, double(dynamic->frames.size() - 1));
  // Only the warm-up frame and frame 0 (the same eye: no motion) may update; every later frame moves 5 m.
  EXPECT_LE(updates, 2.0);
  for (size_t k = 1; k < dynamic->frames.size(); ++k) {
    EXPECT_EQ(dynamic->frames[k].triangles, mmi->frames[k].triangles) << "frame " << k;
    EXPECT_EQ(dynamic->errors[k].psnr_db, mmi->errors[k].psnr_db) << "frame " << k;
  }
}

// The contract's fallback: under a bound no impostor can keep (a ten-thousandth of a pixel), every layer and the single
// mesh are drawn as their objects' geometry, so each frame is the geometry of the cell's potentially visible set:
// no impostor triangle, no parallax, and the image of the `visible` mode (near and far objects as geometry).
TEST_F(MmiModeTest, WhereNoImpostorIsValidTheObjectsAreDrawnAsGeometry) {
  const MmiCity& s = mmiCity();
  const BenchResult strict = runModes(s.path, {"visible", "smi", "mmi"}, s.store, {{"error_px", "0.0001"}});
  const BenchResult loose = runModes(s.path, {"mmi"}, s.store);
  const ModeResult* visible = strict.mode("visible");
  ASSERT_TRUE(visible && strict.mode("smi") && strict.mode("mmi") && loose.mode("mmi"));
  for (const char* name : {"smi", "mmi"}) {
    const ModeResult* m = strict.mode(name);
    SCOPED_TRACE(name);
    EXPECT_EQ(m->info.at("mean_impostor_triangles"), 0.0);
    EXPECT_GT(m->info.at("invalid_layer_draws"), 0.0);
    EXPECT_EQ(m->info.at("unchecked_layer_draws"), 0.0);
    EXPECT_EQ(m->info.at("error_bound_px"), 0.0001);
    ASSERT_EQ(m->errors.size(), visible->errors.size());
    for (size_t k = 0; k < m->errors.size(); ++k) {
      EXPECT_NEAR(m->errors[k].psnr_db, visible->errors[k].psnr_db, 1e-9) << "frame " << k;
      EXPECT_NEAR(m->crack_shares[k], visible->crack_shares[k], 1e-12) << "frame " << k;
    }
  }
  // At the bake's bound the same store draws impostors (the check above is not vacuous).
  EXPECT_GT(loose.mode("mmi")->info.at("mean_impostor_triangles"), 0.0);
  EXPECT_EQ(loose.mode("mmi")->info.at("error_bound_px"), pipelineOptions().error_px);

  // The frames that drew an impostor: none at the strict bound (and no stretch); at the bake's, the frames whose plan
  // drew one, their longest stretch a run of consecutive path frames (every frame measured here).
  for (const char* name : {"smi", "mmi"}) {
    EXPECT_EQ(strict.mode(name)->info.at("frames_with_impostors"), 0.0) << name;
    EXPECT_EQ(strict.mode(name)->info.count("impostor_stretch_first_frame"), 0u) << name;
  }
  const std::map<std::string, double>& info = loose.mode("mmi")->info;
  const double with = info.at("frames_with_impostors"), stretch = info.at("impostor_stretch_frames");
  EXPECT_GT(with, 0.0);
  EXPECT_LE(with, double(s.path.frames.size()));
  EXPECT_GE(stretch, 1.0);
  EXPECT_LE(stretch, with);
  EXPECT_EQ(info.at("impostor_stretch_last_frame") - info.at("impostor_stretch_first_frame") + 1.0, stretch);
  // Frame by frame in the bench's records (frames.csv's impostors column): the same count; none for visible.
  size_t marked = 0;
  for (const FrameRecord& f : loose.mode("mmi")->frames) marked += f.impostors == 1 ? 1 : 0;
  EXPECT_EQ(double(marked), with);
  for (const FrameRecord& f : strict.mode("mmi")->frames) EXPECT_EQ(f.impostors, 0);
  // Against the walkthrough itself, frame by frame: the frames whose plan holds an impostor layer.
  {
    gpu::sharedHeadlessContext().makeCurrent();
    const scene::Scene& scene = s.city.scene;
    const gpu::GpuScene gpu_scene(scene);
    const scene::Bvh bvh(scene);
    gpu::Renderer renderer;
    runtime::WalkthroughOptions o;
    o.database = s.store;
    o.representation = runtime::Representation::Mmi;
    runtime::Walkthrough walkthrough(scene, gpu_scene, bvh, renderer, o);
    size_t expected = 0;
    for (size_t f = 0; f < s.path.frames.size(); ++f) {
      const runtime::FramePlan& plan = walkthrough.plan(s.path.camera(f, kFrameSize, kFrameSize));
      expected += std::any_of(plan.layers.begin(), plan.layers.end(), [](const runtime::LayerDecision& d) {
                    return std::holds_alternative<runtime::LayerAsImpostor>(d);
                  })
                      ? 1
                      : 0;
    }
    EXPECT_EQ(with, double(expected));
  }
}

// The bench's sample frames: besides the evenly spaced ones, the first measured frame that drew an impostor, with a
// PNG per mode (the report shows it).
TEST_F(MmiModeTest, TheFirstFrameWithAnImpostorIsASampleFrame) {
  const MmiCity& s = mmiCity();
  registerImpostorModes();
  BenchOptions options;
  options.modes = {"visible", "mmi"};
  options.width = options.height = kFrameSize;
  options.samples = 1;
  options.out_dir = test::scratchDir("mmi_mode_samples").string();
  options.mode_options["impostor_dir"] = s.store;
  const BenchResult r = runBench(gpu::sharedHeadlessContext(), s.city.scene, s.path, options);
  const ModeResult* mmi = r.mode("mmi");
  ASSERT_TRUE(mmi);
  size_t first = s.path.frames.size();
  for (const FrameRecord& f : mmi->frames)
    if (f.impostors == 1) first = std::min(first, f.path_frame);
  ASSERT_LT(first, s.path.frames.size()) << "no frame drew an impostor";
  const auto it = std::find_if(r.samples.begin(), r.samples.end(),
                               [&](const SampleFrame& sf) { return sf.path_frame == first; });
  ASSERT_NE(it, r.samples.end()) << "frame " << first << " is not a sample";
  EXPECT_LE(r.samples.size(), 2u);
  ASSERT_EQ(it->mode_png.count("mmi"), 1u);
  EXPECT_TRUE(std::filesystem::exists(std::filesystem::path(options.out_dir) / it->mode_png.at("mmi")));
  // visible draws none by design: its frames say so.
  for (const FrameRecord& f : r.mode("visible")->frames) EXPECT_EQ(f.impostors, -1);
}

// Governed over mmi with a budget no frame keeps: every frame at the coarsest level, drawn by the inner mode whose bound
// is the largest impostor level's, at half the resolution. The frames that drew an impostor are the governed frames'
// (not those of the inner mode at the promised bound, which draws only the calibration): at least as many as mmi's at
// the promised bound, since a larger bound and larger pixels only widen where an impostor is valid.
TEST_F(MmiModeTest, GovernedFramesCountTheImpostorsOfTheLevelThatDrewThem) {
  const MmiCity& s = mmiCity();
  const BenchResult r = runModes(s.path, {"mmi", "governed"}, s.store,
                                 {{"governed", "mmi"}, {"governor_t_max_ms", "0.001"}, {"governor_impostor_px", "8"}});
  const ModeResult* mmi = r.mode("mmi");
  const ModeResult* governed = r.mode("governed");
  ASSERT_TRUE(mmi && governed);
  const double levels = governed->info.at("governor_levels");
  EXPECT_EQ(governed->info.at("governor_level_" + std::to_string(int(levels) - 1) + "_frames"),
            governed->info.at("governor_frames"));  // every frame, the warm-up's too
  EXPECT_GE(mmi->info.at("frames_with_impostors"), 2.0);
  EXPECT_GE(governed->info.at("frames_with_impostors"), mmi->info.at("frames_with_impostors"));
  EXPECT_LE(governed->info.at("frames_with_impostors"), double(s.path.frames.size()));
  // Frame by frame: the governed records say what the level that drew them drew.
  size_t marked = 0;
  for (const FrameRecord& f : governed->frames) {
    EXPECT_GE(f.impostors, 0) << "frame " << f.path_frame;
    marked += f.impostors == 1 ? 1 : 0;
  }
  EXPECT_EQ(double(marked), governed->info.at("frames_with_impostors"));
}

// `bake --online single,mmi`: the store holds the PVS and the split; the mode runs the stage it draws (mmi or single,
// not both) when it enters a cell.
TEST_F(MmiModeTest, OnlineStoreRunsTheMissingStagesAndMatchesTheBakedStore) {
  const MmiCity& s = mmiCity();
  const BenchResult baked = runModes(s.path, {"mmi", "smi"}, s.store);
  const BenchResult online = runModes(s.path, {"mmi", "smi", "local"}, s.online_store);
  for (const char* name : {"smi", "mmi"}) {
    SCOPED_TRACE(name);
    const ModeResult* b = baked.mode(name);
    const ModeResult* o = online.mode(name);
    ASSERT_TRUE(b && o);
    EXPECT_EQ(o->info.at("online_runs"), double(s.visited.size()));
    EXPECT_NEAR(o->psnr_db_mean, b->psnr_db_mean, 0.5);
    EXPECT_NEAR(o->mean_triangles, b->mean_triangles, 0.01 * b->mean_triangles);
  }
  const ModeResult* b = baked.mode("mmi");
  const ModeResult* o = online.mode("mmi");
  std::printf("mmi: baked store %.2f dB, %.0f triangles; online store %.2f dB, %.0f triangles, %.0f online runs "
              "(%.1f ms each)\n",
              b->psnr_db_mean, b->mean_triangles, o->psnr_db_mean, o->mean_triangles, o->info.at("online_runs"),
              o->info.at("online_ms_mean"));
  EXPECT_GE(o->info.at("online_runs"), 1.0);
  EXPECT_EQ(o->info.at("online_runs"), double(s.visited.size()));
  EXPECT_GT(o->info.at("online_ms_mean"), 0.0);
  EXPECT_EQ(o->info.at("fallback_frames"), 0.0);
  EXPECT_NEAR(o->psnr_db_mean, b->psnr_db_mean, 0.5);
  EXPECT_NEAR(o->mean_triangles, b->mean_triangles, 0.01 * b->mean_triangles);
  // local needs only near-far, which was baked: nothing runs online for it.
  EXPECT_EQ(online.mode("local")->info.at("online_runs"), 0.0);
}

// The plans' geometry drawn through the arena on the GPU (geometry=gpu, the default) or culled on the CPU
// (geometry=cpu) gives the same frames: the same error against the reference on every frame, the same cracks.
TEST_F(MmiModeTest, GeometryOnTheGpuDrawsTheFramesOfGeometryOnTheCpu) {
  const MmiCity& s = mmiCity();
  const BenchResult gpu = runModes(s.path, {"visible", "mmi"}, s.store, {{"geometry", "gpu"}});
  const BenchResult cpu = runModes(s.path, {"visible", "mmi"}, s.store, {{"geometry", "cpu"}});
  for (const char* name : {"visible", "mmi"}) {
    SCOPED_TRACE(name);
    const ModeResult* g = gpu.mode(name);
    const ModeResult* c = cpu.mode(name);
    ASSERT_TRUE(g && c);
    EXPECT_EQ(g->info.at("geometry_gpu"), 1.0);
    EXPECT_EQ(c->info.at("geometry_gpu"), 0.0);
    EXPECT_GT(g->info.at("geometry_uploads"), 0.0);  // the plan changes along the walk ...
    EXPECT_LE(g->info.at("geometry_uploads"), double(g->frames.size() + 1));  // ... at most once a frame
    ASSERT_EQ(g->errors.size(), c->errors.size());
    for (size_t k = 0; k < g->errors.size(); ++k) {
      EXPECT_NEAR(g->errors[k].psnr_db, c->errors[k].psnr_db, 0.5) << "frame " << k;
      EXPECT_NEAR(g->crack_shares[k], c->crack_shares[k], 1e-4) << "frame " << k;
      EXPECT_EQ(g->frames[k].syncs, 0u) << "frame " << k;
    }
  }
}

TEST_F(MmiModeTest, BadStoresAndOptionsAreErrors) {
  const MmiCity& s = mmiCity();
  registerImpostorModes();
  ModeContext context;
  context.scene = &s.city.scene;
  for (const char* mode : {"local", "visible", "smi", "mmi", "mmi-dynamic"})
    EXPECT_THROW(createMode(mode, context), Error) << mode;  // no impostor_dir

  context.options["impostor_dir"] = s.store;
  for (const auto& [key, value] : std::vector<std::pair<std::string, std::string>>{
           {"frame_budget_ms", "abc"},
           {"frame_budget_ms", "-5"},
           {"frame_budget_ms", "10ms"},
           {"dynamic_error_px", "x"},
           {"dynamic_max_updates", "0"},
           {"dynamic_min_lifetime", "nan"},
           {"impostor_ids", "triangle"},
           {"gpu_budget_mb", "0"},
           {"read_ahead", "maybe"},
           {"cell_lookup", "closest"}}) {
    ModeContext bad = context;
    bad.options[key] = value;
    try {
      createMode("mmi-dynamic", bad);
      ADD_FAILURE() << key << "=" << value << " should be an error";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  }
  EXPECT_NO_THROW(createMode("mmi-dynamic", context));

  // Modes need a GL context and the harness's resources to prepare.
  gpu::sharedHeadlessContext().makeCurrent();
  ModeRunResources run(s.city.scene, kFrameSize, kFrameSize, context.options);

  // (A store of Sillion records, which has no pipeline, is refused by every mode: tests/eval/test_impostor_mode.cpp.)
  // A pipeline without the single and mmi stages serves local and visible, not the impostor modes, each of which
  // names the stage it needs.
  const std::string no_mmi = test::scratchDir("mmi_mode_no_mmi").string();
  extract::PipelineOptions po = pipelineOptions();
  po.base.resolution = 32;
  po.grid_cells = 8;
  bake::bakePipeline(gpu::sharedHeadlessContext(), s.city.scene, *s.cells, {s.visited.front()},
                     extract::parsePipeline("pvs,near-far"), po, no_mmi);
  run.context.options["impostor_dir"] = no_mmi;
  EXPECT_NO_THROW(createMode("local", run.context)->prepare(run.context));
  EXPECT_NO_THROW(createMode("visible", run.context)->prepare(run.context));
  for (const auto& [mode, stage] : std::vector<std::pair<std::string, std::string>>{
           {"smi", "no single stage"}, {"mmi", "no mmi stage"}, {"mmi-dynamic", "no mmi stage"}}) {
    try {
      createMode(mode, run.context)->prepare(run.context);
      ADD_FAILURE() << mode << " should refuse a pipeline without its stage";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(stage), std::string::npos) << e.what();
    }
  }
  // The single stage serves smi; mmi still needs its own.
  const std::string single_only = test::scratchDir("mmi_mode_single_only").string();
  bake::bakePipeline(gpu::sharedHeadlessContext(), s.city.scene, *s.cells, {s.visited.front()},
                     extract::parsePipeline("pvs,near-far,single"), po, single_only);
  run.context.options["impostor_dir"] = single_only;
  EXPECT_NO_THROW(createMode("smi", run.context)->prepare(run.context));
  EXPECT_THROW(createMode("mmi", run.context)->prepare(run.context), Error);
  // A missing directory, and a scene other than the one baked.
  run.context.options["impostor_dir"] = (fs::path(s.store) / "missing").string();
  EXPECT_THROW(createMode("mmi", run.context)->prepare(run.context), Error);
  scene::Scene other = s.city.scene;
  other.objects.pop_back();
  ModeContext other_context = run.context;
  other_context.scene = &other;
  other_context.options["impostor_dir"] = s.store;
  EXPECT_THROW(createMode("mmi", other_context)->prepare(other_context), Error);
  // mmi_dir overrides impostor_dir for these modes.
  run.context.options["impostor_dir"] = "/nonexistent";
  run.context.options["mmi_dir"] = s.store;
  EXPECT_NO_THROW(createMode("mmi", run.context)->prepare(run.context));
}

}  // namespace
}  // namespace farfield::eval
