// A pipeline bake of a small generated city checked against independent computations: item buffers for the PVS,
// the local model for the split, sampled viewing angles for the layers' weights, clip-space box tests for the view.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "farfield/bake/pipeline.h"
#include "farfield/core/error_bound.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/renderer.h"
#include "farfield/store/impostor_store.h"
#include "farfield/urban/cells.h"
#include "farfield/urban/visibility_events.h"
#include "bake/pipeline_fixture.h"

namespace farfield::bake {
using namespace farfield::extract;
namespace {

using pipeline_test::BakedCity;
using pipeline_test::bakedCity;
using pipeline_test::PipelineBakeTest;

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

}  // namespace
}  // namespace farfield::bake
