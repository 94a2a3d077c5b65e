// The extractor pipeline (Decoret et al. 1999, sections 4-5): stage parsing; a pipeline bake of a small generated city
// checked against independent computations (item buffers for the PVS, the local model for the split, sampled viewing
// angles for the layers' visibility-event weights, clip-space box tests for the street frustum, file sizes for the
// storage report); and a store whose mmi stage is left online gives the same layers when the runtime finishes it.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>

#include "farfield/bake/bake.h"
#include "farfield/bake/pipeline.h"
#include "farfield/core/error_bound.h"
#include "farfield/core/error.h"
#include "farfield/gen/camera_path.h"
#include "farfield/gen/city.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/renderer.h"
#include "farfield/store/impostor_store.h"
#include "farfield/urban/cells.h"
#include "farfield/urban/visibility_events.h"
#include "support/expect_error.h"
#include "support/test_support.h"

namespace fs = std::filesystem;

namespace farfield::bake {
using namespace farfield::extract;
namespace {

using test::expectErrorMentions;

// ---------------------------------------------------------------------------------------------------------------
// parsePipeline

// Expects parsePipeline to throw a farfield::Error whose message contains `what` (the option it names).
void expectParseError(const std::string& stages, const std::string& online, const std::string& what) {
  try {
    parsePipeline(stages, online);
    ADD_FAILURE() << "expected farfield::Error for --pipeline '" << stages << "' --online '" << online << "'";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(what), std::string::npos)
        << "--pipeline '" << stages << "' --online '" << online << "': " << e.what();
  }
}

TEST(PipelineParseTest, AcceptsTheValidPipelinesAndSplits) {
  using V = std::vector<std::string>;
  PipelineSpec s = parsePipeline("pvs,near-far,mmi");
  EXPECT_EQ(s.stages, (V{"pvs", "near-far", "mmi"}));
  EXPECT_EQ(s.online_from, 3u);
  EXPECT_EQ(s.baked(), (V{"pvs", "near-far", "mmi"}));
  EXPECT_TRUE(s.online().empty());

  s = parsePipeline("near-far,mmi");
  EXPECT_EQ(s.stages, (V{"near-far", "mmi"}));
  EXPECT_EQ(s.online_from, 2u);

  s = parsePipeline("pvs,near-far");
  EXPECT_EQ(s.stages, (V{"pvs", "near-far"}));
  EXPECT_TRUE(s.online().empty());

  s = parsePipeline("pvs", "");
  EXPECT_EQ(s.stages, (V{"pvs"}));

  s = parsePipeline("pvs,near-far,mmi", "mmi");
  EXPECT_EQ(s.online_from, 2u);
  EXPECT_EQ(s.baked(), (V{"pvs", "near-far"}));
  EXPECT_EQ(s.online(), (V{"mmi"}));

  s = parsePipeline("pvs,near-far,mmi", "near-far,mmi");
  EXPECT_EQ(s.online_from, 1u);
  EXPECT_EQ(s.baked(), (V{"pvs"}));
  EXPECT_EQ(s.online(), (V{"near-far", "mmi"}));

  s = parsePipeline("near-far,mmi", "mmi");
  EXPECT_EQ(s.baked(), (V{"near-far"}));
  EXPECT_EQ(s.online(), (V{"mmi"}));

  // Everything online but the PVS-less pipeline's first stage is allowed too.
  s = parsePipeline("near-far,mmi", "near-far,mmi");
  EXPECT_TRUE(s.baked().empty());
  EXPECT_EQ(s.online(), (V{"near-far", "mmi"}));

  // The single stage: after near-far, before mmi; alone (Sillion's cell impostor) or with mmi, online like mmi.
  s = parsePipeline("near-far,single");
  EXPECT_EQ(s.stages, (V{"near-far", "single"}));
  s = parsePipeline("pvs,near-far,single");
  EXPECT_EQ(s.stages, (V{"pvs", "near-far", "single"}));
  s = parsePipeline("pvs,near-far,single,mmi");
  EXPECT_EQ(s.stages, (V{"pvs", "near-far", "single", "mmi"}));
  s = parsePipeline(kTechniquePipeline);
  EXPECT_EQ(s.stages, (V{"near-far", "single"}));
  s = parsePipeline("pvs,near-far,single,mmi", "mmi");
  EXPECT_EQ(s.baked(), (V{"pvs", "near-far", "single"}));
  s = parsePipeline("pvs,near-far,single,mmi", "single,mmi");
  EXPECT_EQ(s.online(), (V{"single", "mmi"}));
  s = parsePipeline("near-far,single", "single");
  EXPECT_EQ(s.baked(), (V{"near-far"}));
  EXPECT_EQ(s.online(), (V{"single"}));
}

TEST(PipelineParseTest, RejectsBadPipelinesAndSplits) {
  expectParseError("", "", "--pipeline");
  expectParseError("pvs,near-far,smi", "", "--pipeline");         // unknown stage
  expectParseError("pvs,near-far,smi", "", "smi");
  expectParseError("pvs,,mmi", "", "--pipeline");                  // empty stage name
  expectParseError("pvs,near-far,", "", "--pipeline");             // trailing comma
  expectParseError("PVS,near-far", "", "--pipeline");              // names are case-sensitive
  expectParseError("pvs,near-far,near-far,mmi", "", "--pipeline");  // repeated
  expectParseError("pvs,pvs", "", "twice");
  expectParseError("near-far,pvs,mmi", "", "--pipeline");          // wrong order
  expectParseError("pvs,mmi,near-far", "", "--pipeline");
  expectParseError("mmi", "", "--pipeline");                        // mmi without near-far
  expectParseError("pvs,mmi", "", "near-far");
  // Online stages.
  expectParseError("pvs,near-far,mmi", "near-far", "--online");      // not the tail
  expectParseError("pvs,near-far,mmi", "mmi,near-far", "--online");  // the tail, but out of order
  expectParseError("pvs,near-far,mmi", "mmi,mmi", "--online");
  expectParseError("pvs,near-far,mmi", "pvs", "--online");            // pvs online
  expectParseError("pvs,near-far,mmi", "pvs,near-far,mmi", "--online");
  expectParseError("pvs,near-far", "mmi", "--online");                // not in the pipeline
  expectParseError("pvs,near-far", "mmi", "not in the pipeline");
  expectParseError("pvs,near-far,mmi", "smi", "--online");
  expectParseError("pvs,near-far,mmi", "mmi,", "--online");
  // The single stage: one order (pvs, near-far, single, mmi), near-far before it, online only as part of the tail.
  expectParseError("pvs,near-far,mmi,single", "", "the order is pvs, near-far, single, mmi");
  expectParseError("pvs,near-far,mmi,single", "", "'single' must come before 'mmi'");
  expectParseError("single,near-far", "", "--pipeline");
  expectParseError("single", "", "single needs near-far");
  expectParseError("pvs,single", "", "single needs near-far");
  expectParseError("near-far,single,single", "", "twice");
  expectParseError("pvs,near-far,single,mmi", "single", "--online");  // not the tail
  expectParseError("pvs,near-far,single,mmi", "mmi,single", "--online");
  expectParseError("near-far,mmi", "single", "not in the pipeline");
}

TEST(PipelineParseTest, TechniquesAreTheSingleStageWithTheirMesh) {
  EXPECT_EQ(techniqueMesh("depth-mesh"), LayerMesh::DepthMesh);
  EXPECT_EQ(techniqueMesh("grid-mesh"), LayerMesh::Grid);
  // "both" made one store of two meshes from one capture; a store now holds one mesh kind.
  expectErrorMentions([] { techniqueMesh("both"); }, {"--technique", "both", "twice"});
  expectErrorMentions([] { techniqueMesh("depth"); }, {"--technique", "depth"});
  expectErrorMentions([] { techniqueMesh("grid", "mode 'x'"); }, {"mode 'x'", "grid"});
}

// ---------------------------------------------------------------------------------------------------------------
// A small city, baked

// A 16-block city of plain boxes with one object per building (several objects per block: layers with several
// members, pairs with and without visibility events), a 24-frame drive (5 m per frame), and the cells it visits
// baked twice with the full pipeline: all stages baked, and with the single and mmi stages left online. Built once
// for the suite.
struct BakedCity {
  gen::City city;
  std::unique_ptr<urban::CellMap> cells;
  std::vector<uint32_t> visited;
  PipelineOptions options;
  std::string full_dir, online_dir;
  PipelineReport full_report, online_report;
  double full_s = 0.0, online_s = 0.0;
};

// A layer captured with LayerViews::Street from its stations: one view and one validity region per station, the
// first at the cell's start, the others on the cell at increasing distances, each region's origin its station's eye.
void expectStations(const store::StoredLayer& layer, const Vec3& p_eye, const Vec3& q_eye) {
  ASSERT_FALSE(layer.validity.empty());
  ASSERT_EQ(layer.views.size(), layer.validity.size());
  float last = -1.0f;
  for (size_t v = 0; v < layer.views.size(); ++v) {
    const store::StoredView& view = layer.views[v];
    ASSERT_EQ(view.station, v);
    EXPECT_EQ(layer.validity[v].origin, view.camera.eye);
    const float along = glm::length(Vec2(view.camera.eye) - Vec2(p_eye));
    EXPECT_GT(along, last);
    EXPECT_LT(along, glm::length(Vec2(q_eye) - Vec2(p_eye)));
    if (v == 0) {
      EXPECT_LT(glm::length(view.camera.eye - p_eye), 1e-3f);
    }
    last = along;
  }
}

PipelineOptions smallOptions() {
  PipelineOptions o;
  o.base.resolution = 128;
  o.base.progress = false;
  o.pvs.spacing = 8.0f;
  o.pvs.face_size = 64;
  o.error_px = 10.0;  // 10 px in 512 x 512 frames at 60 degrees, the paper's setting
  o.frame_width = 512;
  o.frame_height = 512;
  o.grid_cells = 30;
  return o;
}

const BakedCity& bakedCity() {
  static const BakedCity* b = [] {
    auto* c = new BakedCity;
    gen::CityOptions o;
    o.blocks = 16;
    o.detail = 0;
    o.seed = 3;
    o.objects = gen::ObjectGrouping::Buildings;
    c->city = gen::generateCity(o);
    c->cells = std::make_unique<urban::CellMap>(c->city.streets, c->city.scene);
    gen::StreetWalkOptions walk;
    walk.frames = 24;
    walk.walker = gen::Walker::Car;
    walk.fps = 2.0f;
    walk.seed = 2;
    c->visited = cellsOnPath(*c->cells, gen::streetWalk(c->city.streets, walk));
    c->options = smallOptions();
    c->full_dir = test::scratchDir("pipeline_full").string();
    c->online_dir = test::scratchDir("pipeline_online").string();
    auto t0 = std::chrono::steady_clock::now();
    c->full_report = bakePipeline(gpu::sharedHeadlessContext(), c->city.scene, *c->cells, c->visited,
                                  parsePipeline("pvs,near-far,single,mmi"), c->options, c->full_dir);
    auto t1 = std::chrono::steady_clock::now();
    c->online_report = bakePipeline(gpu::sharedHeadlessContext(), c->city.scene, *c->cells, c->visited,
                                    parsePipeline("pvs,near-far,single,mmi", "single,mmi"), c->options,
                                    c->online_dir);
    auto t2 = std::chrono::steady_clock::now();
    c->full_s = std::chrono::duration<double>(t1 - t0).count();
    c->online_s = std::chrono::duration<double>(t2 - t1).count();
    return c;
  }();
  return *b;
}

bool contains(const std::vector<uint32_t>& sorted, uint32_t id) {
  return std::binary_search(sorted.begin(), sorted.end(), id);
}

bool strictlyAscending(const std::vector<uint32_t>& ids) {
  return std::adjacent_find(ids.begin(), ids.end(), [](uint32_t a, uint32_t b) { return a >= b; }) == ids.end();
}

// The footprint the weights are computed on: the object's own, else its bounds' rectangle.
Polygon2 footprintOf(const scene::Object& object) {
  if (!object.footprint.empty()) return object.footprint;
  const Box3& b = object.world_bounds;
  return {{b.lo.x, b.lo.y}, {b.hi.x, b.lo.y}, {b.hi.x, b.hi.y}, {b.lo.x, b.hi.y}};
}

// w_ij by brute force: 0 unless one footprint meets the other's critical zone; otherwise the largest variation, over
// M sampled densely on [PQ], of the angle AMB, over every pair of footprint vertices (A of i, B of j). Sampling can
// only miss a little of an extremum, so this is at most the exact weight (up to ~1e-6 relative here).
double bruteForceWeight(const Polygon2& a, const Polygon2& b, const urban::CellSegment& cell) {
  if (!urban::intersectsConvex(b, urban::criticalZone(a, cell)) &&
      !urban::intersectsConvex(a, urban::criticalZone(b, cell)))
    return 0.0;
  constexpr int kSamples = 2001;
  const DVec2 p(cell.p), q(cell.q);
  double weight = 0.0;
  for (const Vec2& va : a)
    for (const Vec2& vb : b) {
      double lo = 10.0, hi = -1.0;
      for (int s = 0; s < kSamples; ++s) {
        const DVec2 m = p + (q - p) * (double(s) / double(kSamples - 1));
        const DVec2 ma = DVec2(va) - m, mb = DVec2(vb) - m;
        const double angle = std::atan2(std::abs(cross2(ma, mb)), glm::dot(ma, mb));
        lo = std::min(lo, angle);
        hi = std::max(hi, angle);
      }
      weight = std::max(weight, hi - lo);
    }
  return weight;
}

// The box against the camera's clip-space half-spaces (-w <= x, y <= w, 0 <= z <= w): each is linear in the world
// point, so a box with all eight corners outside one of them misses the frustum, and a box with a corner inside all
// of them meets it.
enum class FrustumSide { Outside, Inside, Unknown };
FrustumSide frustumSide(const Camera& camera, const Box3& box) {
  const Mat4 vp = camera.viewProjection();
  std::array<Vec4, 8> clip;
  for (int k = 0; k < 8; ++k) {
    const Vec3 corner((k & 1) ? box.hi.x : box.lo.x, (k & 2) ? box.hi.y : box.lo.y, (k & 4) ? box.hi.z : box.lo.z);
    clip[size_t(k)] = vp * Vec4(corner, 1.0f);
  }
  const auto all = [&](auto outside) {
    return std::all_of(clip.begin(), clip.end(), [&](const Vec4& c) { return outside(c); });
  };
  if (all([](const Vec4& c) { return c.x > c.w; }) || all([](const Vec4& c) { return c.x < -c.w; }) ||
      all([](const Vec4& c) { return c.y > c.w; }) || all([](const Vec4& c) { return c.y < -c.w; }) ||
      all([](const Vec4& c) { return c.z > c.w; }) || all([](const Vec4& c) { return c.z < 0.0f; }))
    return FrustumSide::Outside;
  for (const Vec4& c : clip)
    if (c.w > 0.0f && std::abs(c.x) <= c.w && std::abs(c.y) <= c.w && c.z >= 0.0f && c.z <= c.w)
      return FrustumSide::Inside;
  return FrustumSide::Unknown;
}

// Ids covering at least `min_pixels` pixels of a 360-degree item-buffer view from `eye` (six 90-degree faces of
// `face` pixels, the test's own cameras).
std::set<uint32_t> seenAround(const gpu::GpuScene& gpu_scene, const Vec3& eye, int face, size_t min_pixels) {
  gpu::Renderer renderer;
  gpu::RenderTarget target(face, face);
  const std::vector<gpu::DrawItem> items = gpu_scene.drawItems();
  const Vec3 dirs[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  std::map<uint32_t, size_t> pixels;
  for (const Vec3& d : dirs) {
    Camera c;
    c.eye = eye;
    c.at = eye + d;
    c.up = std::abs(d.z) > 0.5f ? Vec3(0, 1, 0) : Vec3(0, 0, 1);
    c.fov_y = float(degToRad(90.0));
    c.width = c.height = face;
    c.near_plane = 0.25f;
    c.far_plane = 20000.0f;
    renderer.render(c, items, target, gpu::RenderMode::ItemBuffer);
    const image::IdImage ids = target.readIds();
    for (uint32_t id : ids.pixels())
      if (id != 0) ++pixels[id];
  }
  std::set<uint32_t> out;
  for (const auto& [id, n] : pixels)
    if (n >= min_pixels) out.insert(id);
  return out;
}

uint64_t fileBytes(const std::string& dir, const std::string& name) {
  if (name.empty()) return 0;
  const fs::path p = fs::path(dir) / name;
  EXPECT_TRUE(fs::is_regular_file(p)) << p;
  return fs::is_regular_file(p) ? uint64_t(fs::file_size(p)) : 0;
}

class PipelineBakeTest : public ::testing::Test {
 protected:
  void SetUp() override { gpu::sharedHeadlessContext(); }
};

TEST_F(PipelineBakeTest, BakedCellsHoldAConsistentPvsSplitAndLayering) {
  const BakedCity& b = bakedCity();
  ASSERT_GE(b.visited.size(), 2u);
  const store::StoreIndex index = store::readIndex(b.full_dir);
  EXPECT_EQ(index.version, store::kIndexVersion);
  EXPECT_EQ(index.pipeline, (std::vector<std::string>{"pvs", "near-far", "single", "mmi"}));
  EXPECT_TRUE(index.online.empty());
  EXPECT_EQ(index.scene_objects, b.city.scene.objects.size());
  ASSERT_EQ(index.cells.size(), b.full_report.cells.size());
  ASSERT_EQ(index.cells.size(), b.visited.size() - b.full_report.skipped_degenerate.size());
  const double threshold = b.full_report.threshold_rad;
  EXPECT_NEAR(threshold, (ErrorBound{10.0, 512, 512, degToRad(60.0)}).angle(), 1e-12);

  const scene::Scene& scene = b.city.scene;
  const size_t n = scene.objects.size();
  const gpu::GpuScene gpu_scene(scene);
  size_t layered_cells = 0, max_layers = 0, checked_pairs = 0, conflicting_layer_pairs = 0;
  size_t seen_checked = 0, far_inside = 0, far_outside = 0;
  double max_in_layer = 0.0;
  for (const store::CellEntry& e : index.cells) {
    SCOPED_TRACE("cell " + std::to_string(e.half_edge));
    ASSERT_TRUE(e.pipeline);
    const store::CellPipeline& p = *e.pipeline;
    ASSERT_TRUE(p.has_pvs && p.has_split && p.has_single && p.has_mmi);
    EXPECT_EQ(e.local_objects, b.cells->localObjects(e.half_edge));

    // PVS: ids in range, ascending; near and far partition it.
    EXPECT_TRUE(strictlyAscending(p.pvs));
    EXPECT_TRUE(strictlyAscending(p.near));
    EXPECT_TRUE(strictlyAscending(p.far));
    ASSERT_FALSE(p.pvs.empty());
    EXPECT_GE(p.pvs.front(), 1u);
    EXPECT_LE(p.pvs.back(), n);
    std::vector<uint32_t> both;
    std::set_union(p.near.begin(), p.near.end(), p.far.begin(), p.far.end(), std::back_inserter(both));
    EXPECT_EQ(both, p.pvs) << "near and far must cover the PVS";
    std::vector<uint32_t> common;
    std::set_intersection(p.near.begin(), p.near.end(), p.far.begin(), p.far.end(), std::back_inserter(common));
    EXPECT_TRUE(common.empty()) << "near and far overlap";
    // Near is the PVS's part of the local model, far the rest.
    const std::vector<uint32_t> local = b.cells->localObjects(e.half_edge);
    for (uint32_t id : p.near) EXPECT_TRUE(contains(local, id)) << "near object " << id << " is not local";
    for (uint32_t id : p.far) EXPECT_FALSE(contains(local, id)) << "far object " << id << " is local";
    // The ground is always seen.
    for (uint32_t id : b.cells->assignment().shared) EXPECT_TRUE(contains(p.near, id)) << "shared " << id;

    // The PVS holds what an item buffer of the test's own sees from both ends of the cell (both are sample points).
    // Objects of one or two pixels may differ with the cube's orientation, so only those of 3 pixels or more count.
    const Vec3 p_eye = e.camera.eye;
    const Vec2 q2 = b.cells->graph().destinationPosition(e.half_edge);
    const Vec3 q_eye(q2, p_eye.z);  // flat city: the same eye height at both ends
    for (const Vec3& eye : {p_eye, q_eye})
      for (uint32_t id : seenAround(gpu_scene, eye, b.options.pvs.face_size, 3)) {
        ++seen_checked;
        EXPECT_TRUE(contains(p.pvs, id)) << "object " << id << " seen from (" << eye.x << ", " << eye.y
                                         << ") is not in the PVS";
      }

    // Layers: disjoint, inside far, covering every far object the street view certainly meets and none it certainly
    // misses; the single mesh holds them all.
    const Camera& street = e.camera;
    std::vector<uint32_t> layered;
    for (const store::StoredLayer& l : p.layers) {
      EXPECT_TRUE(strictlyAscending(l.objects));
      EXPECT_FALSE(l.objects.empty());
      layered.insert(layered.end(), l.objects.begin(), l.objects.end());
      expectStations(l, e.camera.eye, q_eye);
    }
    std::sort(layered.begin(), layered.end());
    EXPECT_TRUE(strictlyAscending(layered)) << "an object is in two layers";
    for (uint32_t id : layered) EXPECT_TRUE(contains(p.far, id)) << "layered object " << id << " is not far";
    for (uint32_t id : p.far) {
      const FrustumSide side = frustumSide(street, scene.objects[id - 1].world_bounds);
      far_inside += side == FrustumSide::Inside ? 1 : 0;
      far_outside += side == FrustumSide::Outside ? 1 : 0;
      if (side == FrustumSide::Inside) {
        EXPECT_TRUE(contains(layered, id)) << "far object " << id << " in view";
      } else if (side == FrustumSide::Outside) {
        EXPECT_FALSE(contains(layered, id)) << "far object " << id << " out of view";
      }
    }
    EXPECT_EQ(p.single.objects, layered);
    expectStations(p.single, e.camera.eye, q_eye);

    // Visibility-event weights, recomputed: every pair within a layer is at most T; and the greedy layering never
    // opens a layer it did not need, so every two layers hold a pair above T.
    const urban::CellSegment segment{b.cells->graph().originPosition(e.half_edge),
                                     b.cells->graph().destinationPosition(e.half_edge)};
    std::vector<Polygon2> footprints(n + 1);
    for (uint32_t id : layered) footprints[id] = footprintOf(scene.objects[id - 1]);
    for (const store::StoredLayer& l : p.layers)
      for (size_t i = 0; i < l.objects.size(); ++i)
        for (size_t j = i + 1; j < l.objects.size(); ++j) {
          const double w = bruteForceWeight(footprints[l.objects[i]], footprints[l.objects[j]], segment);
          max_in_layer = std::max(max_in_layer, w);
          ++checked_pairs;
          EXPECT_LE(w, threshold * (1.0 + 1e-9))
              << "objects " << l.objects[i] << " and " << l.objects[j] << " share a layer with w = " << w;
        }
    for (size_t la = 0; la < p.layers.size(); ++la)
      for (size_t lb = la + 1; lb < p.layers.size(); ++lb) {
        double worst = 0.0;
        for (uint32_t i : p.layers[la].objects)
          for (uint32_t j : p.layers[lb].objects)
            worst = std::max(worst, bruteForceWeight(footprints[i], footprints[j], segment));
        EXPECT_GT(worst, threshold * 0.99) << "layers " << la << " and " << lb << " could have been one";
        ++conflicting_layer_pairs;
      }
    // The event graph over the same objects: as many related pairs (w > 0) as the brute force finds, the same
    // largest weight. (Here every related pair is above T: the streets are short and the blocks close.)
    size_t related = 0;
    double max_weight = 0.0;
    for (size_t i = 0; i < layered.size(); ++i)
      for (size_t j = i + 1; j < layered.size(); ++j) {
        const double w = bruteForceWeight(footprints[layered[i]], footprints[layered[j]], segment);
        related += w > 1e-9 ? 1 : 0;
        max_weight = std::max(max_weight, w);
      }
    EXPECT_EQ(p.event_edges, related);
    EXPECT_NEAR(p.max_weight_rad, max_weight, 1e-3 * max_weight + 1e-9);
    EXPECT_GT(p.max_weight_rad, threshold);
    if (p.layers.size() >= 2) ++layered_cells;
    max_layers = std::max(max_layers, p.layers.size());
    EXPECT_EQ(p.threshold_rad, threshold);

    // Each view's files are there, with the counts of the index.
    for (const store::StoredLayer& l : p.layers)
      for (const store::StoredView& v : l.views) {
        const impostor::DepthMeshImpostor imp = store::loadLayerView(b.full_dir, v);
        EXPECT_EQ(imp.camera.eye, v.camera.eye);
        EXPECT_EQ(imp.camera.eye, l.validity.at(v.station).origin);
        if (v.data_pixels > 0) {
          EXPECT_GT(v.triangles, 0u);
        }
      }
  }
  // The checks above must have had something to check.
  EXPECT_GE(layered_cells, 1u) << "no cell has two layers or more";
  EXPECT_GT(seen_checked, 0u);
  EXPECT_GT(far_inside, 0u);
  EXPECT_GT(far_outside, 0u);
  std::printf("pipeline bake: %zu cells in %.2f s (online split: %.2f s); up to %zu layers, %zu in-layer pairs "
              "checked (max w %.4f rad, T %.4f), %zu layer pairs with a conflict; %zu item-buffer ids in the PVS, "
              "far objects: "
              "%zu in view, %zu out of view\n",
              index.cells.size(), b.full_s, b.online_s, max_layers, checked_pairs, max_in_layer, threshold,
              conflicting_layer_pairs, seen_checked, far_inside, far_outside);
  for (const PipelineCellReport& r : b.full_report.cells)
    std::printf("  cell %u: pvs %zu, near %zu, far %zu, layers %zu, %zu + %zu triangles\n", r.half_edge, r.pvs, r.near,
                r.far, r.layers, r.layer_triangles, r.single_triangles);
}

TEST_F(PipelineBakeTest, StorageReportCountsTheBytesWritten) {
  const BakedCity& b = bakedCity();
  const store::StoreIndex index = store::readIndex(b.full_dir);
  uint64_t textures = 0, meshes = 0, ids = 0;
  size_t layers = 0, views = 0;
  std::set<std::string> referenced;
  for (const store::CellEntry& e : index.cells) {
    ASSERT_TRUE(e.pipeline && e.pipeline->has_mmi);
    layers += e.pipeline->layers.size();
    auto add = [&](const store::StoredView& v) {
      textures += fileBytes(b.full_dir, v.texture);
      meshes += fileBytes(b.full_dir, v.mesh);
      ids += fileBytes(b.full_dir, v.ids);
      if (!v.texture.empty()) referenced.insert(v.texture);
      if (!v.ids.empty()) referenced.insert(v.ids);
      // A view with data carries its per-texel object ids.
      EXPECT_EQ(v.ids.empty(), v.texture.empty()) << v.mesh;
      referenced.insert(v.mesh);
    };
    for (const store::StoredLayer& l : e.pipeline->layers)
      for (const store::StoredView& v : l.views) {
        add(v);
        ++views;
      }
    for (const store::StoredView& v : e.pipeline->single.views) add(v);
  }
  // Every file under cells/ is referenced (nothing written that the index does not know of).
  uint64_t on_disk = 0;
  for (const auto& f : fs::directory_iterator(fs::path(b.full_dir) / "cells")) {
    const std::string name = "cells/" + f.path().filename().string();
    EXPECT_TRUE(referenced.count(name)) << name << " is not referenced by the index";
    on_disk += uint64_t(f.file_size());
  }
  const nlohmann::json& s = index.storage;
  ASSERT_TRUE(s.is_object());
  EXPECT_EQ(s.at("written_texture_bytes").get<uint64_t>(), textures);
  EXPECT_EQ(s.at("written_mesh_bytes").get<uint64_t>(), meshes);
  EXPECT_EQ(s.at("written_bytes").get<uint64_t>(), textures + meshes);
  EXPECT_EQ(s.at("written_id_bytes").get<uint64_t>(), ids);
  EXPECT_EQ(on_disk, textures + meshes + ids);
  EXPECT_GT(textures, 0u);
  EXPECT_EQ(b.full_report.storage, s);
  EXPECT_EQ(s.at("cells").get<size_t>(), index.cells.size());
  EXPECT_EQ(s.at("layers").get<size_t>(), layers);
  // The paper's estimate (section 5.1): RGB images of resolution^2 and a 30 x 30 grid of float xyz (10.8 kB).
  const double image = 128.0 * 128.0 * 3.0, mesh = 30.0 * 30.0 * 12.0;
  EXPECT_DOUBLE_EQ(s.at("mesh_bytes_each").get<double>(), 10800.0);
  EXPECT_DOUBLE_EQ(s.at("estimate_bytes_measured_layers").get<double>(), double(views) * (image + mesh));
  EXPECT_DOUBLE_EQ(s.at("estimate_bytes_3_layers").get<double>(), double(index.cells.size()) * 3.0 * (image + mesh));
  std::printf("storage: %zu views, %llu texture + %llu mesh bytes written; estimate %.0f bytes (3 layers: %.0f)\n",
              views, (unsigned long long)textures, (unsigned long long)meshes,
              s.at("estimate_bytes_measured_layers").get<double>(), s.at("estimate_bytes_3_layers").get<double>());
}

TEST_F(PipelineBakeTest, OnlineSingleAndMmiStoreHoldsPvsAndSplitAndTheRuntimeFinishesItIdentically) {
  const BakedCity& b = bakedCity();
  const store::StoreIndex full = store::readIndex(b.full_dir);
  const store::StoreIndex online = store::readIndex(b.online_dir);
  EXPECT_EQ(online.pipeline, (std::vector<std::string>{"pvs", "near-far", "single", "mmi"}));
  EXPECT_EQ(online.online, (std::vector<std::string>{"single", "mmi"}));
  ASSERT_EQ(online.cells.size(), full.cells.size());
  for (const store::CellEntry& e : online.cells) {
    ASSERT_TRUE(e.pipeline);
    EXPECT_TRUE(e.pipeline->has_pvs);
    EXPECT_TRUE(e.pipeline->has_split);
    EXPECT_FALSE(e.pipeline->has_mmi) << "cell " << e.half_edge;
    EXPECT_FALSE(e.pipeline->has_single) << "cell " << e.half_edge;
    EXPECT_TRUE(e.pipeline->layers.empty());
    EXPECT_TRUE(e.pipeline->single.views.empty());
  }
  // No image or mesh written, and the storage report says so.
  size_t files = 0;
  if (fs::is_directory(fs::path(b.online_dir) / "cells"))
    for ([[maybe_unused]] const auto& f : fs::directory_iterator(fs::path(b.online_dir) / "cells")) ++files;
  EXPECT_EQ(files, 0u);
  EXPECT_EQ(online.storage.at("written_bytes").get<uint64_t>(), 0u);
  EXPECT_EQ(b.online_report.cells.size(), b.full_report.cells.size());

  // The runtime's path: the runner resumed from the stored record, the online stages run; the same layers as the
  // bake's, for every cell.
  const gpu::GpuScene gpu_scene(b.city.scene);
  const PipelineOptions options = pipelineOptionsFromJson(online.options.at("pipeline"), "online index");
  PipelineRunner runner(b.city.scene, gpu_scene, *b.cells, options);
  EXPECT_DOUBLE_EQ(runner.threshold(), b.full_report.threshold_rad);
  for (const store::CellEntry& e : online.cells) {
    SCOPED_TRACE("cell " + std::to_string(e.half_edge));
    const store::CellEntry* baked = full.find(e.half_edge);
    ASSERT_NE(baked, nullptr);
    // The stages both bakes ran agree.
    EXPECT_EQ(e.pipeline->pvs, baked->pipeline->pvs);
    EXPECT_EQ(e.pipeline->near, baked->pipeline->near);
    EXPECT_EQ(e.pipeline->far, baked->pipeline->far);
    CellWork work = runner.resume(e.half_edge, *e.pipeline);
    EXPECT_EQ(work.candidates, e.pipeline->far);
    runner.runStages(online.online, work);
    const store::CellPipeline& r = work.result;
    ASSERT_TRUE(r.has_mmi);
    ASSERT_EQ(r.layers.size(), baked->pipeline->layers.size());
    for (size_t l = 0; l < r.layers.size(); ++l) {
      EXPECT_EQ(r.layers[l].objects, baked->pipeline->layers[l].objects) << "layer " << l;
      ASSERT_EQ(r.layers[l].views.size(), baked->pipeline->layers[l].views.size());
      for (size_t v = 0; v < r.layers[l].views.size(); ++v)
        EXPECT_EQ(r.layers[l].views[v].triangles, baked->pipeline->layers[l].views[v].triangles) << "layer " << l;
    }
    ASSERT_TRUE(r.has_single);
    EXPECT_EQ(r.single.objects, baked->pipeline->single.objects);
    ASSERT_EQ(r.single.views.size(), baked->pipeline->single.views.size());
    for (size_t v = 0; v < r.single.views.size(); ++v) {
      EXPECT_EQ(r.single.views[v].triangles, baked->pipeline->single.views[v].triangles) << "single view " << v;
      EXPECT_EQ(r.single.views[v].station, baked->pipeline->single.views[v].station) << "single view " << v;
    }
    EXPECT_EQ(r.single.validity.size(), baked->pipeline->single.validity.size());
    EXPECT_EQ(work.layer_views.size(), r.layers.size());
    EXPECT_EQ(work.single_views.size(), r.single.views.size());
    EXPECT_TRUE(work.layer_captures.empty());  // buildMeshes ran and freed them
    EXPECT_TRUE(work.single_captures.empty());
  }
}

TEST_F(PipelineBakeTest, OptionsSurviveTheIndexAndBadOptionsAreErrors) {
  const BakedCity& b = bakedCity();
  PipelineOptions o = smallOptions();
  o.error_px = 7.5;
  o.frame_width = 300;
  o.near_radius = 25.0f;
  o.mesh = LayerMesh::DepthMesh;
  o.views = LayerViews::Six;
  o.layer_order = urban::LayerOrder::Given;
  o.layer_choice = urban::LayerChoice::SmallestArea;
  o.events.points = urban::RepresentativePoints::HullVertices;
  o.events.landmark_boost = 3.0;
  const PipelineOptions back = pipelineOptionsFromJson(nlohmann::json::parse(pipelineOptionsToJson(o).dump()), "x");
  EXPECT_EQ(back.base.resolution, o.base.resolution);
  EXPECT_EQ(back.error_px, o.error_px);
  EXPECT_EQ(back.frame_width, o.frame_width);
  EXPECT_EQ(back.near_radius, o.near_radius);
  EXPECT_EQ(back.mesh, o.mesh);
  EXPECT_EQ(back.views, o.views);
  EXPECT_EQ(back.layer_order, o.layer_order);
  EXPECT_EQ(back.layer_choice, o.layer_choice);
  EXPECT_EQ(back.events.points, o.events.points);
  EXPECT_EQ(back.events.landmark_boost, o.events.landmark_boost);
  EXPECT_EQ(back.pvs.spacing, o.pvs.spacing);
  EXPECT_EQ(back.pvs.face_size, o.pvs.face_size);
  EXPECT_EQ(back.grid_cells, o.grid_cells);
  EXPECT_EQ(back.frame_height, o.frame_height);
  EXPECT_EQ(back.frame_fov_deg, o.frame_fov_deg);
  EXPECT_EQ(back.validity.step, o.validity.step);
  EXPECT_EQ(back.validity.laterals, o.validity.laterals);
  EXPECT_EQ(back.validity.below, o.validity.below);
  EXPECT_EQ(back.base.capture.detect_seen_from_below, o.base.capture.detect_seen_from_below);
  EXPECT_THROW(pipelineOptionsFromJson({{"error_px", "ten"}}, "x"), Error);
  EXPECT_THROW(pipelineOptionsFromJson({{"layer_mesh", "voxels"}}, "x"), Error);
  EXPECT_THROW(pipelineOptionsFromJson(nlohmann::json::array(), "x"), Error);
  // Saved whole, read back strictly: every key missing, changed to a wrong type or joined by an unknown one is an
  // error naming it; no silent default.
  const nlohmann::json whole = pipelineOptionsToJson(o);
  for (const auto& [key, value] : whole.items()) {
    nlohmann::json j = whole;
    j.erase(key);
    expectErrorMentions([&] { pipelineOptionsFromJson(j, "idx"); }, {"idx", key});
    j = whole;
    j[key] = nlohmann::json::array({"?"});
    expectErrorMentions([&] { pipelineOptionsFromJson(j, "idx"); }, {"idx", key});
  }
  {
    nlohmann::json j = whole;
    j["error_pixels"] = 3;
    expectErrorMentions([&] { pipelineOptionsFromJson(j, "idx"); }, {"idx", "unknown", "error_pixels"});
    j = whole;
    j["validity"]["stride"] = 3;
    expectErrorMentions([&] { pipelineOptionsFromJson(j, "idx"); }, {"idx", "unknown", "stride"});
    j = whole;
    j["grid_cells"] = 2.5;
    expectErrorMentions([&] { pipelineOptionsFromJson(j, "idx"); }, {"idx", "grid_cells", "integer"});
    j = whole;
    j["layer_order"] = "random";
    expectErrorMentions([&] { pipelineOptionsFromJson(j, "idx"); }, {"idx", "layer_order", "random"});
  }
  {
    // A version 2 store had no frame height, frame field of view or validity sampling: square frames at fov_deg.
    nlohmann::json v2 = whole;
    v2.erase("frame_height");
    v2.erase("frame_fov_deg");
    v2.erase("validity");
    v2.erase("station_spacing");
    EXPECT_THROW(pipelineOptionsFromJson(v2, "idx"), Error);
    // Versions 2 and 3 also said whether the mmi stage built the single mesh (now the single stage: the store's
    // reader maps it); required there, a boolean, and unknown in version 4.
    expectErrorMentions([&] { pipelineOptionsFromJson(v2, "idx", 2); }, {"idx", "single_mesh", "missing"});
    v2["single_mesh"] = "yes";
    expectErrorMentions([&] { pipelineOptionsFromJson(v2, "idx", 2); }, {"idx", "single_mesh", "true or false"});
    v2["single_mesh"] = false;
    const PipelineOptions old = pipelineOptionsFromJson(v2, "idx", 2);
    EXPECT_EQ(old.frame_height, old.frame_width);
    EXPECT_EQ(old.frame_fov_deg, o.base.fov_deg);
    nlohmann::json v3 = whole;
    expectErrorMentions([&] { pipelineOptionsFromJson(v3, "idx", 3); }, {"idx", "single_mesh", "missing"});
    v3["single_mesh"] = true;
    EXPECT_EQ(pipelineOptionsFromJson(v3, "idx", 3).mesh, o.mesh);
    expectErrorMentions([&] { pipelineOptionsFromJson(v3, "idx", 4); }, {"idx", "unknown", "single_mesh"});
  }

  const std::string dir = test::scratchDir("pipeline_bad").string();
  const auto bake = [&](const PipelineOptions& options, std::vector<uint32_t> cells) {
    bakePipeline(gpu::sharedHeadlessContext(), b.city.scene, *b.cells, std::move(cells),
                 parsePipeline("pvs,near-far,single,mmi"), options, dir);
  };
  PipelineOptions bad = smallOptions();
  bad.error_px = 0.0;
  EXPECT_THROW(bake(bad, {b.visited.front()}), Error);
  bad = smallOptions();
  bad.grid_cells = 129;  // more grid cells than pixels
  EXPECT_THROW(bake(bad, {b.visited.front()}), Error);
  bad = smallOptions();
  bad.near_radius = -1.0f;
  EXPECT_THROW(bake(bad, {b.visited.front()}), Error);
  EXPECT_THROW(bake(smallOptions(), {uint32_t(b.cells->cellCount())}), Error);  // no such cell
  // mmi before near-far, on the runner directly.
  const gpu::GpuScene gpu_scene(b.city.scene);
  PipelineRunner runner(b.city.scene, gpu_scene, *b.cells, smallOptions());
  CellWork work = runner.start(b.visited.front());
  expectErrorMentions([&] { runner.runStage(kStageMmi, work); }, {"mmi needs the near-far stage"});
  expectErrorMentions([&] { runner.runStage(kStageSingle, work); }, {"single needs the near-far stage"});
  EXPECT_THROW(runner.runStage("smi", work), Error);
  EXPECT_THROW(runner.start(uint32_t(b.cells->cellCount())), Error);
}

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
