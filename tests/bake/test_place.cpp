// Automatic impostor placement end to end (bake/place.h): a small city with a hand-made cost profile (so the times
// are the model's, not this machine's noise), placed under a frame budget and an error bound, then walked with the
// runtime's Placed representation. Checked independently of the placement's own bookkeeping:
//   - every sampled view of the view space, planned by the runtime, is predicted (by the same profile, from what the
//     plan actually draws) under t_max wherever its CPV was solved or no CPV holds it;
//   - the impostors drawn keep the error bound against full geometry (parallax of item buffers);
//   - the database reads back with the options that made it, strictly.
#include "farfield/bake/place.h"
#include "farfield/placement/visibility_cache.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>
#include <set>
#include <utility>
#include <span>
#include <variant>

#include "farfield/core/error.h"
#include "farfield/eval/parallax_error.h"
#include "farfield/gen/city.h"
#include "farfield/gpu/gpu_culler.h"
#include "farfield/gpu/occlusion_culler.h"
#include "farfield/gpu/render_target.h"
#include "farfield/impostor/layered_fill.h"
#include "farfield/runtime/walkthrough.h"
#include "farfield/scene/bvh.h"
#include "farfield/store/placement_store.h"
#include "support/small_placement.h"
#include "support/test_support.h"

namespace farfield::bake {
namespace {

struct Placed {
  gen::City city;
  gpu::CostProfile profile;
  PlaceOptions options;
  PlaceReport report;
  std::string dir;
};

const Placed& placed() {
  static const Placed* s = [] {
    auto* c = new Placed;
    c->city = test::smallPlacementCity();
    c->profile = test::handProfile();
    c->options = test::smallPlaceOptions(c->city.scene);
    PlaceOptions& p = c->options;
    c->dir = test::scratchDir("place_city").string();
    c->report = placeImpostors(gpu::sharedHeadlessContext(), c->city.scene, c->profile, p, c->dir);
    return c;
  }();
  return *s;
}

TEST(PlaceTest, ProblemViewsExistAndMostAreSolved) {
  const Placed& s = placed();
  const PlaceReport& r = s.report;
  EXPECT_GT(r.cpvs, 10u);
  EXPECT_GT(r.impostors, 0u);
  EXPECT_LT(r.unsolved_cpvs, r.cpvs);  // placement solved some problem views
  EXPECT_GT(r.t_enc_max_ms, s.options.t_max_ms);
  EXPECT_GT(r.visibility_regions, 0u);
  const store::PlacementIndex index = store::readPlacementIndex(s.dir);
  EXPECT_EQ(index.cpvs.size(), r.cpvs);
  EXPECT_EQ(index.impostors.size(), r.impostors);
  size_t solved = 0;
  for (const store::StoredCpv& c : index.cpvs) {
    EXPECT_LE(c.t_after, c.t_enc + 1e-9);
    if (c.t_after <= s.options.t_max_ms) ++solved;
  }
  EXPECT_EQ(solved, r.cpvs - r.unsolved_cpvs);
  // What the memory holds, counted again from the database's images: texels, covered texels, id textures.
  uint64_t texels = 0, covered = 0, id_texels = 0;
  for (const store::StoredPlacedImpostor& stored : index.impostors) {
    const impostor::LayeredImpostor imp = store::loadPlacedImpostor(s.dir, stored);
    for (const impostor::Layer& layer : imp.layers) {
      texels += layer.color.pixelCount();
      for (const image::Rgba8& p : layer.color.pixels()) covered += p.a > 0 ? 1 : 0;
      id_texels += layer.ids.pixelCount();
    }
  }
  EXPECT_EQ(r.stored_texels, texels);  // the layers as stored: cropped to their data
  EXPECT_LT(r.stored_texels, r.layer_texels);
  EXPECT_LT(r.memory_bytes, r.estimated_bytes);
  EXPECT_EQ(r.covered_texels, covered);
  EXPECT_GT(covered, 0u);
  EXPECT_LT(covered, texels);
  EXPECT_EQ(id_texels, texels);  // id textures on (the default): as many id texels as colour texels
  EXPECT_GT(r.id_texture_bytes, 4.0 * double(texels) - 1.0);  // 4 bytes an id texel, atlas padding on top
  EXPECT_LE(r.id_texture_bytes, 0.5 * r.memory_bytes);
  // The options that made it, back strictly.
  EXPECT_EQ(placeOptionsToJson(placeOptionsFromJson(index.options, "index")), index.options);
  nlohmann::json extra = index.options;
  extra["colour"] = 1;
  EXPECT_THROW(placeOptionsFromJson(extra, "index"), Error);
  nlohmann::json missing = index.options;
  missing.erase("t_max_ms");
  EXPECT_THROW(placeOptionsFromJson(missing, "index"), Error);
  // A database placed before the visibility grid was an option sampled the corners and the centre.
  EXPECT_EQ(index.options.at("visibility_grid"), 4);
  nlohmann::json before = index.options;
  before.erase("visibility_grid");
  EXPECT_EQ(placeOptionsFromJson(before, "index").visibility_grid, 2);
  // One placed before layers were drawn as their tiles charged whole quads.
  EXPECT_EQ(index.options.at("layer_tiles"), true);
  before.erase("layer_tiles");
  EXPECT_FALSE(placeOptionsFromJson(before, "index").layer_tiles);
}

struct ViewChecks {
  size_t guarded = 0, with_impostors = 0;
  size_t checked_images = 0, over_tolerance = 0;  // views compared with full geometry; p99 over bound + one texel
  uint64_t hidden_triangles = 0;
  double worst_parallax = 0.0;
};

// `views` random views of the database's view space planned by the runtime: where the CPV was solved (or no CPV holds
// the view) the plan is predicted under t_max by the profile; where impostors are drawn (the first 40 such views) the
// parallax against full geometry is measured (p99 of the object pixels, counted when over the bound plus one texel),
// and the plan's geometry drawn through the occlusion culler with its impostors after it gives the same item buffer
// as the plan drawn whole.
ViewChecks checkViews(const scene::Scene& scene, const gpu::CostProfile& profile, const PlaceOptions& place_options,
                      const std::string& dir, int views) {
  gpu::sharedHeadlessContext().makeCurrent();
  const gpu::GpuScene gpu_scene(scene);
  const scene::Bvh bvh(scene);
  gpu::Renderer renderer;
  runtime::WalkthroughOptions options = test::placedWalkthroughOptions(dir);
  runtime::Walkthrough walkthrough(scene, gpu_scene, bvh, renderer, options);
  const store::PlacementIndex index = store::readPlacementIndex(dir);
  const Box3 space = index.view_space;
  gpu::RenderTarget target(128, 128), reference_target(128, 128), culled_target(128, 128);
  gpu::OcclusionCuller culler;
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  ViewChecks out;
  size_t checked_images = 0;
  for (int k = 0; k < views; ++k) {
    Camera camera;
    camera.eye = space.lo + (space.hi - space.lo) * Vec3(u(rng), u(rng), u(rng));
    const float yaw = float(2.0 * kPi) * u(rng);
    camera.at = camera.eye + Vec3(std::cos(yaw), std::sin(yaw), 0.0f);
    camera.width = camera.height = 128;
    camera.fov_y = float(degToRad(45.0));
    const runtime::FramePlan& plan = walkthrough.plan(camera);
    uint64_t triangles = 0;
    for (const gpu::DrawItem& item : plan.items) triangles += item.triangleCount();
    const double predicted = profile.boundMs(double(triangles), double(plan.items.size()), 128.0 * 128.0,
                                             test::itemsFill(plan.items, scene, camera));
    const bool solved = plan.report.cpv == urban::kNone || plan.report.cpv_t_after_ms <= place_options.t_max_ms;
    if (solved) {
      ++out.guarded;
      EXPECT_LE(predicted, place_options.t_max_ms + 1e-9) << "view " << k << " cpv " << plan.report.cpv;
    }
    if (plan.report.cpv != urban::kNone && plan.report.impostor_triangles > 0) {
      ++out.with_impostors;
      if (checked_images < 40) {
        // Against full geometry: what the impostors show stays within the bound (item buffers; the ground, drawn
        // as geometry in both, left out; one texel of quantisation allowed beyond the bound).
        // The reference: full geometry of what the runtime draws there (the region's sampled visible set, which
        // placement and runtime both use; what that sampling misses is measured by the bench as cracks), with the
        // impostors' objects as geometry.
        std::vector<uint32_t> ids;
        const std::optional<uint32_t> leaf = store::lookupLeaf(index, camera.eye);
        if (leaf && index.nodes[*leaf].has_visible) ids = index.nodes[*leaf].visible;
        for (const runtime::LayerDecision& d : plan.layers)
          if (const auto* i = std::get_if<runtime::ClusterAsImpostor>(&d))
            for (uint32_t o : index.find(i->impostor)->objects) ids.push_back(o);
        ids.push_back(1);  // the ground
        std::sort(ids.begin(), ids.end());
        ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
        std::vector<gpu::DrawItem> reference;
        gpu_scene.appendDrawItems(ids, reference);
        renderer.render(camera, plan.items, target);
        renderer.render(camera, reference, reference_target);
        eval::ParallaxOptions po;
        po.ignore_ids = {1};
        const eval::ParallaxError e = eval::parallaxError(reference_target.readIds(), target.readIds(), po);
        out.worst_parallax = std::max(out.worst_parallax, e.object_percentile_px);
        if (e.object_percentile_px > place_options.error_px + place_options.layered.texel_pixels) ++out.over_tolerance;
        ++checked_images;
        ++out.checked_images;
        // The plan's geometry through the occlusion culler and its impostors after it: the same item buffer.
        EXPECT_EQ(plan.geometry_bounds.size(), plan.geometry_items);
        if (plan.geometry_bounds.size() != plan.geometry_items) continue;
        const std::span<const gpu::DrawItem> all(plan.items);
        culled_target.clear(Vec4(0.0f));
        out.hidden_triangles += culler
                                    .draw(renderer, camera, all.first(plan.geometry_items), plan.geometry_bounds,
                                          culled_target, all.subspan(plan.geometry_items))
                                    .hidden_triangles;
        const image::IdImage want = target.readIds(), got = culled_target.readIds();
        EXPECT_TRUE(std::equal(want.pixels().begin(), want.pixels().end(), got.pixels().begin())) << "view " << k;
      }
    }
  }
  return out;
}

TEST(PlaceTest, EveryViewKeepsBothPromisesWhereItsProblemWasSolved) {
  const Placed& s = placed();
  const ViewChecks v = checkViews(s.city.scene, s.profile, s.options, s.dir, 300);
  EXPECT_GT(v.guarded, 30u);
  EXPECT_GT(v.with_impostors, 5u);
  EXPECT_GT(v.hidden_triangles, 0u);  // the comparison saw culled frames
  EXPECT_EQ(v.over_tolerance, 0u);
  std::printf("guarded views %zu, with impostors %zu, worst parallax p99 %.2f px\n", v.guarded, v.with_impostors,
              v.worst_parallax);
}

// A plan for a GPU-driven frame over the placement (geometry as objects): the region's visible set less what the
// impostors drawn stand for, with no frustum query, culled and drawn by gpu::GpuCuller with the plan's impostors after
// it, gives the frame of the plan's items (culled on the CPU) pixel for pixel; and its list changes only when the
// region or the impostors drawn do, not as the camera turns or moves inside a region.
TEST(PlaceTest, AGpuDrivenPlanListsItsRegionsObjectsAndDrawsTheSameFrame) {
  const Placed& s = placed();
  const scene::Scene& scene = s.city.scene;
  gpu::sharedHeadlessContext().makeCurrent();
  const gpu::GpuScene gpu_scene(scene);
  const scene::Bvh bvh(scene);
  const gpu::SceneArena arena(scene);
  gpu::GpuCuller culler(arena);
  gpu::Renderer renderer;
  runtime::WalkthroughOptions options = test::placedWalkthroughOptions(s.dir);
  runtime::Walkthrough with_items(scene, gpu_scene, bvh, renderer, options);
  options.geometry_items = false;
  runtime::Walkthrough with_objects(scene, gpu_scene, bvh, renderer, options);
  const store::PlacementIndex index = store::readPlacementIndex(s.dir);
  const Box3 space = index.view_space;
  gpu::RenderTarget target(128, 128), reference_target(128, 128);
  uint64_t version = 0;
  size_t list_changes = 0, key_changes = 0, impostor_frames = 0;
  std::pair<uint32_t, std::vector<uint32_t>> last_key{~uint32_t(1), {}};  // no region has that index
  const int frames = 120;
  for (int f = 0; f < frames; ++f) {
    SCOPED_TRACE("frame " + std::to_string(f));
    const Camera camera = test::viewSpaceWalkCamera(space, f, frames);
    const runtime::FramePlan& a = with_items.plan(camera);
    renderer.render(camera, a.items, reference_target);
    const runtime::FramePlan& b = with_objects.plan(camera);
    EXPECT_EQ(b.geometry_items, 0u);
    EXPECT_TRUE(std::is_sorted(b.geometry_objects.begin(), b.geometry_objects.end()));
    for (size_t i = 0; i < a.geometry_items; ++i)
      EXPECT_TRUE(std::binary_search(b.geometry_objects.begin(), b.geometry_objects.end(), a.items[i].object_id));
    ASSERT_EQ(b.items.size(), a.items.size() - a.geometry_items);  // the same impostors
    impostor_frames += !b.items.empty();
    list_changes += b.geometry_version != version;
    version = b.geometry_version;
    std::pair<uint32_t, std::vector<uint32_t>> key{store::lookupLeaf(index, camera.eye).value_or(~uint32_t(0)), {}};
    for (const runtime::LayerDecision& d : b.layers)
      if (const auto* i = std::get_if<runtime::ClusterAsImpostor>(&d)) key.second.push_back(i->impostor);
    key_changes += key != last_key;
    last_key = key;
    culler.setObjects(b.geometry_objects);
    target.bind();
    target.clear(renderer.light().sky_color);
    culler.draw(camera, target, gpu::RenderMode::Shaded, renderer.light());
    renderer.draw(camera, b.items, target);
    EXPECT_EQ(target.readIds().pixels(), reference_target.readIds().pixels());
    EXPECT_EQ(target.readColor().pixels(), reference_target.readColor().pixels());
  }
  EXPECT_GT(impostor_frames, 0u);  // the walk draws impostors: the lists lose their objects
  EXPECT_LE(list_changes, key_changes);
  EXPECT_LT(list_changes, size_t(frames) / 4);
  std::printf("%d frames: %zu list changes, %zu region or impostor changes, %zu frames with impostors\n", frames,
              list_changes, key_changes, impostor_frames);
}

// The small city placed again with other candidate view cells (shafts and/or boxes) into a scratch folder.
struct Replaced {
  PlaceOptions options;
  PlaceReport report;
  std::string dir;
};
Replaced placeWithViewCells(bool shafts, bool boxes, const char* dir_name) {
  const Placed& s = placed();
  Replaced out;
  out.options = s.options;
  out.options.candidates.shafts = shafts;
  out.options.candidates.rectangular_cells = boxes;
  out.dir = test::scratchDir(dir_name).string();
  out.report = placeImpostors(gpu::sharedHeadlessContext(), s.city.scene, s.profile, out.options, out.dir);
  return out;
}

// No view cells (`place --view-cells none`, the control of what impostors add): the same problem view space and
// visible sets as the placement with candidates, no impostor, every CPV's time as estimated.
TEST(PlaceTest, WithoutViewCellsTheViewSpaceIsTheSameAndNothingIsPlaced) {
  const Placed& s = placed();
  const Replaced none_cells = placeWithViewCells(false, false, "place_none");
  EXPECT_EQ(none_cells.report.candidate_counts.considered, 0u);
  EXPECT_EQ(none_cells.report.impostors, 0u);
  EXPECT_EQ(none_cells.report.unsolved_cpvs, none_cells.report.cpvs);
  const store::PlacementIndex none = store::readPlacementIndex(none_cells.dir);
  const store::PlacementIndex with = store::readPlacementIndex(s.dir);
  ASSERT_EQ(none.cpvs.size(), with.cpvs.size());
  for (size_t c = 0; c < none.cpvs.size(); ++c) {
    EXPECT_EQ(none.cpvs[c].t_enc, with.cpvs[c].t_enc) << c;
    EXPECT_EQ(none.cpvs[c].t_after, none.cpvs[c].t_enc) << c;
    EXPECT_TRUE(none.cpvs[c].impostors.empty()) << c;
  }
  ASSERT_EQ(none.nodes.size(), with.nodes.size());
  for (size_t n = 0; n < none.nodes.size(); ++n) EXPECT_EQ(none.nodes[n].visible, with.nodes[n].visible) << n;
}

// Rectangular view cells (the paper's test 13): the view space's regions as box cells, each planned through the shaft
// from the cluster's centre around it. Checked:
//   - every CPV that shows an impostor lies in that impostor's shaft;
//   - the promise of the layered plan, by brute force: from viewpoints sampled in those CPVs' regions, points of the
//     cluster's box are seen within the plan's error angle (<= the bound) of where their layer draws them (the point
//     where the capture eye's ray through them meets the layer's plane);
//   - the views keep the frame budget as with shafts, and the item buffers against full geometry stay within the bound
//     plus a texel in all but one view in twenty. (Seen here: 128x128 frames of clusters 200-350 m away, where a facade
//     seen edge-on is a one-pixel sliver that a neighbour in the same slab covers from the capture eye; the sliver's
//     pixels then measure the distance to the rest of its object, 5-8 px, though every point is drawn within the
//     bound: a crack, which the bench counts as such.)
TEST(PlaceTest, BoxViewCellsArePlannedThroughTheShaftAroundThem) {
  const Placed& s = placed();
  const Replaced boxes = placeWithViewCells(false, true, "place_boxes");
  const PlaceOptions& options = boxes.options;
  const PlaceReport& r = boxes.report;
  const std::string& dir = boxes.dir;
  EXPECT_GT(r.candidate_counts.kept, 0u);
  EXPECT_GT(r.impostors, 0u);
  EXPECT_LT(r.unsolved_cpvs, r.cpvs);
  const store::PlacementIndex index = store::readPlacementIndex(dir);
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  size_t shown = 0, pairs = 0;
  double worst_ratio = 0.0;
  for (const store::StoredCpv& c : index.cpvs)
    for (uint32_t id : c.impostors) {
      const store::StoredPlacedImpostor& rec = *index.find(id);
      EXPECT_TRUE(rec.shaft.containsBox(c.region));
      ++shown;
      const impostor::LayeredPlan lp = impostor::planLayered(rec.box, rec.shaft, rec.bound, rec.options);
      const DVec3 e(lp.capture_eye), apex(lp.shaft.apex), axis(lp.shaft.axis);
      const double d = lp.shaft.min_distance;
      for (int k = 0; k < 20; ++k) {
        const DVec3 eye(c.region.lo + (c.region.hi - c.region.lo) * Vec3(u(rng), u(rng), u(rng)));
        const DVec3 p(rec.box.lo + (rec.box.hi - rec.box.lo) * Vec3(u(rng), u(rng), u(rng)));
        const double zp = glm::dot(p - apex, axis);
        const auto layer = std::find_if(lp.layers.begin(), lp.layers.end(), [&](const impostor::LayerPlan& l) {
          return zp >= double(l.z_lo) - 1e-4 && zp <= double(l.z_hi) + 1e-4;
        });
        ASSERT_NE(layer, lp.layers.end());
        const DVec3 q = e + (p - e) * ((d - double(layer->depth)) / (d - zp));
        const DVec3 to_p = p - eye, to_q = q - eye;
        const double angle = std::atan2(glm::length(glm::cross(to_p, to_q)), glm::dot(to_p, to_q));
        EXPECT_LE(angle, lp.error_angle * (1.0 + 1e-6)) << "impostor " << id;
        worst_ratio = std::max(worst_ratio, angle / lp.bound_angle);
        ++pairs;
      }
    }
  EXPECT_GT(shown, 0u);
  EXPECT_LE(worst_ratio, 1.0 + 1e-6);
  const ViewChecks v = checkViews(s.city.scene, s.profile, options, dir, 200);
  EXPECT_GT(v.guarded, 30u);
  EXPECT_GT(v.with_impostors, 3u);
  EXPECT_GT(v.checked_images, 3u);
  EXPECT_LE(v.over_tolerance * 20, v.checked_images);
  std::printf("box cells: %zu candidates, %zu impostors (shafts: %zu), %zu of %zu CPVs unsolved (shafts: %zu), "
              "%.2f MB (shafts: %.2f); %zu sampled pairs, worst parallax %.2f of the bound; item buffers: %zu of %zu "
              "views over the bound plus a texel, worst p99 %.2f px\n",
              r.candidate_counts.kept, r.impostors, s.report.impostors, r.unsolved_cpvs, r.cpvs,
              s.report.unsolved_cpvs, r.memory_bytes / 1048576.0, s.report.memory_bytes / 1048576.0, pairs,
              worst_ratio, v.over_tolerance, v.checked_images, v.worst_parallax);
}

// The fill in the cost model, and the fallback to coarser bounds: with a profile whose layered draw term and geometry
// fill term are dear, every view the runtime plans where its CPV was solved is predicted under t_max from what it
// draws, the impostors' fill and the geometry's fill included (recomputed here from each drawn impostor's plan and
// each drawn object's bounds at the eye's distance: placement charges them from the CPV region's nearest point); the fallback
// passes leave no more CPVs over t_max than the bound alone, and the database's impostors placed under a coarser
// bound are the ones the report counts.
TEST(PlaceTest, LayeredFillIsChargedAndTheFallbackIsCounted) {
  const gen::City city = test::smallPlacementCity();
  gpu::CostProfile profile = test::handProfile();
  profile.layered.calibrated = true;
  profile.layered.draw.ms_per_draw = 0.05;      // per layer
  profile.layered.draw.ms_per_mpixel = 40.0;    // per million pixels of quads
  profile.layered.draw_safety_factor = 1.5;
  profile.model.ms_per_mfill = 8.0;  // per million pixels the drawn objects may cover: a full 128 x 128 frame 0.13 ms
  PlaceOptions options = test::smallPlaceOptions(city.scene);
  options.fallback_bound_factors = {2.0, 4.0};
  const std::string dir = test::scratchDir("place_fill_fallback").string();
  const PlaceReport r = placeImpostors(gpu::sharedHeadlessContext(), city.scene, profile, options, dir);
  EXPECT_TRUE(r.layered_fill_in_model);
  EXPECT_LE(r.unsolved_cpvs, r.unsolved_at_bound);
  const store::PlacementIndex index = store::readPlacementIndex(dir);
  size_t coarse = 0;
  for (const store::StoredPlacedImpostor& imp : index.impostors) coarse += imp.bound.pixels > options.error_px;
  EXPECT_EQ(coarse, r.fallback_impostors);
  size_t unsolved = 0;
  for (const store::StoredCpv& c : index.cpvs) unsolved += c.t_after > options.t_max_ms;
  EXPECT_EQ(unsolved, r.unsolved_cpvs);

  gpu::sharedHeadlessContext().makeCurrent();
  const gpu::GpuScene gpu_scene(city.scene);
  const scene::Bvh bvh(city.scene);
  gpu::Renderer renderer;
  runtime::WalkthroughOptions wo;
  wo.database = dir;
  wo.representation = runtime::Representation::Placed;
  runtime::Walkthrough walkthrough(city.scene, gpu_scene, bvh, renderer, wo);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const auto randomCamera = [&]() {  // in the view space, any heading, level
    Camera camera;
    camera.eye = index.view_space.lo + (index.view_space.hi - index.view_space.lo) * Vec3(u(rng), u(rng), u(rng));
    const float yaw = float(2.0 * kPi) * u(rng);
    camera.at = camera.eye + Vec3(std::cos(yaw), std::sin(yaw), 0.0f);
    camera.width = camera.height = 128;
    camera.fov_y = float(degToRad(45.0));
    return camera;
  };
  size_t guarded = 0, drawn = 0;
  std::set<double> workloads;
  for (int k = 0; k < 400; ++k) {
    const Camera camera = randomCamera();
    const runtime::FramePlan& plan = walkthrough.plan(camera);
    uint64_t triangles = 0;
    for (const gpu::DrawItem& item : plan.items) triangles += item.triangleCount();
    double predicted = profile.boundMs(double(triangles), double(plan.items.size()), 128.0 * 128.0,
                                       test::itemsFill(plan.items, city.scene, camera));
    for (const runtime::LayerDecision& d : plan.layers)
      if (const auto* i = std::get_if<runtime::ClusterAsImpostor>(&d)) {
        const store::StoredPlacedImpostor& rec = *index.find(i->impostor);
        const impostor::LayeredPlan lp = store::storedLayeredPlan(rec);  // the quads as drawn: cropped
        const ErrorBound frame{options.error_px, 128, 128, degToRad(45.0)};
        predicted += profile.layered.drawBoundMs(
            double(lp.quads()), impostor::layeredFillPixels(lp, double(glm::length(camera.eye - rec.shaft.apex)), frame));
        ++drawn;
      }
    if (plan.report.cpv == urban::kNone || plan.report.cpv_t_after_ms <= options.t_max_ms) {
      ++guarded;
      EXPECT_LE(predicted, options.t_max_ms + 1e-9) << "view " << k << " cpv " << plan.report.cpv;
    }
    // What the walkthrough tells a governor before planning (expectedTriangles): the triangles of the visible set of
    // the region holding the eye, counted here from the scene, and at least the plan's geometry.
    const std::optional<uint32_t> leaf = store::lookupLeaf(index, camera.eye);
    double visible_triangles = 0.0;
    for (const scene::Object& o : city.scene.objects)
      if (!leaf || !index.nodes[*leaf].has_visible ||
          std::binary_search(index.nodes[*leaf].visible.begin(), index.nodes[*leaf].visible.end(), o.id))
        for (const scene::Part& part : o.parts) visible_triangles += double(city.scene.meshes[part.mesh].triangleCount());
    const double expected = walkthrough.expectedTriangles(camera.eye);
    EXPECT_EQ(expected, visible_triangles) << "view " << k;
    EXPECT_GE(expected, double(plan.report.geometry_triangles)) << "view " << k;
    workloads.insert(expected);
  }
  EXPECT_GT(guarded, 30u);
  EXPECT_GT(workloads.size(), 2u);  // regions of different visible sets
  std::printf("fill charged: %zu CPVs over t_max at the bound, %zu after the fallback (%zu coarser impostors); %zu "
              "guarded views, %zu impostors drawn\n",
              r.unsolved_at_bound, r.unsolved_cpvs, r.fallback_impostors, guarded, drawn);

  // Without coarser_impostors the walkthrough keeps its bound: the impostors placed under a coarser one are left to
  // geometry, the others drawn as before; raising its bound to theirs takes them again (a governor's coarser level).
  ASSERT_GT(r.fallback_impostors, 0u) << "the check below needs coarser impostors";
  runtime::WalkthroughOptions strict_options = wo, raised_options = wo;
  strict_options.coarser_impostors = raised_options.coarser_impostors = false;
  raised_options.error_px = options.error_px * 4.0;  // the coarsest fallback bound
  runtime::Walkthrough free_walk(city.scene, gpu_scene, bvh, renderer, wo);
  runtime::Walkthrough strict(city.scene, gpu_scene, bvh, renderer, strict_options);
  runtime::Walkthrough raised(city.scene, gpu_scene, bvh, renderer, raised_options);
  const auto coarseOf = [&](uint32_t id) { return index.find(id)->bound.pixels > options.error_px * (1.0 + 1e-9); };
  size_t coarse_drawn = 0, coarse_raised = 0;
  rng.seed(5);
  for (int k = 0; k < 400; ++k) {
    const Camera camera = randomCamera();
    std::set<uint32_t> as_impostor, strict_impostor;
    for (const runtime::LayerDecision& d : free_walk.plan(camera).layers)
      if (const auto* i = std::get_if<runtime::ClusterAsImpostor>(&d)) as_impostor.insert(i->impostor);
    for (const runtime::LayerDecision& d : strict.plan(camera).layers) {
      if (const auto* i = std::get_if<runtime::ClusterAsImpostor>(&d)) {
        EXPECT_FALSE(coarseOf(i->impostor)) << "view " << k << ": impostor " << i->impostor;
        strict_impostor.insert(i->impostor);
      }
    }
    for (uint32_t id : as_impostor) {
      coarse_drawn += coarseOf(id) ? 1 : 0;
      EXPECT_EQ(strict_impostor.count(id), coarseOf(id) ? 0u : 1u) << "view " << k << ": impostor " << id;
    }
    for (const runtime::LayerDecision& d : raised.plan(camera).layers)
      if (const auto* i = std::get_if<runtime::ClusterAsImpostor>(&d)) coarse_raised += coarseOf(i->impostor) ? 1 : 0;
  }
  EXPECT_GT(coarse_drawn, 0u) << "no view drew a coarser impostor: the check is vacuous";
  EXPECT_GE(coarse_raised, coarse_drawn);
  // Every coarser impostor of the eye's CPV is left to geometry, at least those the free walkthrough drew.
  EXPECT_GE(strict.statistics().at("coarser_impostors_left_to_geometry"), double(coarse_drawn));
}

// --visibility-only: every minimum-size region of the view space's partition is sampled into the cache (the regions
// a full placement visits at a budget every view exceeds), each found again from its centre; no database is written.
TEST(PlaceTest, VisibilityOnlySamplesEveryRegionIntoTheCache) {
  const gen::City city = test::smallPlacementCity();
  PlaceOptions options = test::smallPlaceOptions(city.scene);
  const std::string dir = test::scratchDir("place_visibility_only").string();
  options.visibility_cache = dir + "/vis.json";
  options.visibility_only = true;
  const PlaceReport r =
      placeImpostors(gpu::sharedHeadlessContext(), city.scene, gpu::CostProfile{}, options, dir + "/db");
  EXPECT_FALSE(std::filesystem::exists(dir + "/db"));
  const placement::VisibilityCache cache = placement::readVisibilityCache(options.visibility_cache);
  EXPECT_EQ(cache.regions.size(), r.visibility_regions);
  // The same partition from a placement that visits every region (a budget below any view's time).
  PlaceOptions all = test::smallPlaceOptions(city.scene);
  all.t_max_ms = 1e-3;
  all.visibility_cache = dir + "/vis_all.json";
  all.candidates.distance_steps = 1;
  placeImpostors(gpu::sharedHeadlessContext(), city.scene, test::handProfile(), all, dir + "/db_all");
  const placement::VisibilityCache visited = placement::readVisibilityCache(all.visibility_cache);
  EXPECT_EQ(cache.key, visited.key);
  EXPECT_EQ(cache.regions, visited.regions);
  EXPECT_GE(cache.regions.size(), 8u);
  for (const auto& [lo, ids] : cache.regions) {
    const std::optional<Box3> region = cache.regionOf(Vec3(lo[0], lo[1], lo[2]) + Vec3(0.01f));
    ASSERT_TRUE(region.has_value());
    EXPECT_EQ(region->lo, Vec3(lo[0], lo[1], lo[2]));
    EXPECT_FALSE(ids.empty());
  }
  options.visibility_cache.clear();
  EXPECT_THROW(placeImpostors(gpu::sharedHeadlessContext(), city.scene, gpu::CostProfile{}, options, dir + "/db"),
               Error);
}

TEST(PlaceTest, BadOptionsAreErrors) {
  const Placed& s = placed();
  PlaceOptions o = s.options;
  o.t_max_ms = 0.0;
  EXPECT_THROW(placeImpostors(gpu::sharedHeadlessContext(), s.city.scene, s.profile, o,
                              test::scratchDir("place_bad").string()),
               Error);
  o = s.options;
  o.max_pitch_deg = 0.0f;
  EXPECT_THROW(placeImpostors(gpu::sharedHeadlessContext(), s.city.scene, s.profile, o,
                              test::scratchDir("place_bad").string()),
               Error);
  scene::Scene empty;
  EXPECT_THROW(placeImpostors(gpu::sharedHeadlessContext(), empty, s.profile, s.options,
                              test::scratchDir("place_bad").string()),
               Error);
}

}  // namespace
}  // namespace farfield::bake
