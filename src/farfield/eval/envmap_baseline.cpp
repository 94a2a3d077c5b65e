// The per-cell environment-map baseline (envmap_baseline.h).
#include "farfield/eval/envmap_baseline.h"

#include <algorithm>
#include <array>
#include <map>
#include <cmath>
#include <memory>
#include <numeric>
#include <random>

#include "farfield/core/error.h"
#include "farfield/core/log.h"
#include "farfield/core/object_fill.h"
#include "farfield/core/progress.h"
#include "farfield/core/timer.h"
#include "farfield/gpu/renderer.h"
#include "farfield/impostor/layered.h"
#include "farfield/scene/bvh.h"

namespace farfield::eval {
namespace {

nlohmann::json boxJson(const Box3& b) { return {{"lo", {b.lo.x, b.lo.y, b.lo.z}}, {"hi", {b.hi.x, b.hi.y, b.hi.z}}}; }

// Captures one face layer by layer (each layer drawing only the objects its slab meets), cuts every layer to its
// data and returns the cropped plan with each layer's cover measured; adds the covered texels.
impostor::LayeredPlan captureFace(gpu::Renderer& renderer, const gpu::GpuScene& gpu_scene, const scene::Scene& scene,
                                  const impostor::EnvMapFace& face, uint64_t* covered) {
  const impostor::LayeredPlan& plan = face.plan;
  std::vector<impostor::LayerCrop> crops;
  std::vector<float> covers;
  crops.reserve(plan.layers.size());
  for (size_t i = 0; i < plan.layers.size(); ++i) {
    impostor::LayeredPlan one = plan;
    one.layers = {plan.layers[i]};
    one.box = Box3();
    for (uint32_t id : face.layer_objects[i]) one.box.expand(scene.objects[id - 1].world_bounds);
    impostor::packAtlases(one);
    const impostor::LayeredImpostor captured = impostor::captureLayered(renderer, gpu_scene, face.layer_objects[i], one);
    *covered += captured.layers[0].data_texels;
    const impostor::LayerPlan cut = impostor::cropLayered(captured).plan.layers[0];  // its data, its tiles measured
    crops.push_back({cut.crop_x, cut.crop_y, cut.width, cut.height});
    covers.push_back(cut.cover);
  }
  impostor::LayeredPlan cropped = plan;
  impostor::cropLayers(cropped, crops);
  for (size_t i = 0; i < covers.size(); ++i) cropped.layers[i].cover = covers[i];
  return cropped;
}

}  // namespace

nlohmann::json EnvMapBaselineReport::toJson() const {
  nlohmann::json list = nlohmann::json::array();
  for (const EnvMapCell& c : cells)
    list.push_back({{"region", boxJson(c.region)},
                    {"cpvs", c.cpvs},
                    {"far_distance", c.far_distance},
                    {"solved", c.solved},
                    {"t_est_max_ms", c.t_est_max_ms},
                    {"visible_objects", c.visible_objects},
                    {"near_objects", c.near_objects},
                    {"far_objects", c.far_objects},
                    {"faces", c.faces},
                    {"layers", c.layers},
                    {"draws", c.draws},
                    {"planned_bytes", c.planned_bytes},
                    {"bytes", c.bytes},
                    {"stored_texels", c.stored_texels},
                    {"covered_texels", c.covered_texels},
                    {"capture_s", c.capture_s}});
  return {{"t_max_ms", t_max_ms},
          {"bound", {{"pixels", bound.pixels}, {"width", bound.width}, {"height", bound.height}, {"fov_y", bound.fov_y}}},
          {"problem_cells", problem_cells},
          {"all_cells", all_cells},
          {"captured_cells", cells.size()},
          {"unsolved", unsolved},
          {"bytes_captured", bytes_captured},
          {"bytes_estimate", bytes_estimate},
          {"bytes_stderr", bytes_stderr},
          {"placement_bytes", placement_bytes},
          {"placement_total_bytes", placement_total_bytes},
          {"ratio", placement_bytes > 0.0 ? bytes_estimate / placement_bytes : 0.0},
          {"wall_s", wall_s},
          {"cells", list}};
}

EnvMapBaselineReport runEnvMapBaseline(gpu::Context& context, const scene::Scene& scene,
                                       const gpu::CostProfile& profile, const store::PlacementIndex& index,
                                       const ErrorBound& bound, const Lens& lens, double t_max_ms,
                                       const EnvMapBaselineOptions& options) {
  if (index.scene_objects != scene.objects.size())
    throw Error("placement database", "made for a scene of " + std::to_string(index.scene_objects) +
                                          " objects, this one has " + std::to_string(scene.objects.size()));
  if (options.far_distances.empty()) throw Error("--far", "no far-field distance");
  for (double d : options.far_distances)
    if (!(d > 0.0) || !std::isfinite(d)) throw Error("--far", "distances must be finite and > 0 metres");
  if (!(t_max_ms > 0.0)) throw Error("t_max", "must be > 0 ms");
  bound.validate("environment-map baseline error bound");
  Stopwatch wall;
  EnvMapBaselineReport report;
  report.t_max_ms = t_max_ms;
  report.bound = bound;
  for (const store::StoredPlacedImpostor& imp : index.impostors) {
    const double mesh = double(imp.layers.size() * impostor::kLayerQuadBytes);
    const double textures = std::max(0.0, double(imp.bytes) - mesh);
    report.placement_total_bytes += double(imp.bytes);
    report.placement_bytes += mesh + (imp.options.id_textures ? 0.5 : 1.0) * textures;
  }

  // The cells: leaves of the placement's view-space partition that hold CPVs (or the caller's), each with its CPVs.
  struct CellRef {
    Box3 box;
    const std::vector<uint32_t>* visible;
    uint32_t cpv_first = 0, cpv_count = 0;
  };
  std::vector<CellRef> cells;
  std::map<std::array<float, 3>, size_t> problem_by_corner;
  for (size_t n = 0; n < index.nodes.size(); ++n) {
    const store::StoredViewSpaceNode& node = index.nodes[n];
    if (node.children[0] != -1 || node.cpv_count == 0) continue;
    if (!node.has_visible)
      throw Error("placement database", "region " + std::to_string(n) +
                                            " has no visible set (placed without visibility): the baseline culls "
                                            "each cell by it, as the paper's does");
    problem_by_corner[{node.box.lo.x, node.box.lo.y, node.box.lo.z}] = n;
    cells.push_back({node.box, &node.visible, node.cpv_first, node.cpv_count});
  }
  report.problem_cells = cells.size();
  if (!options.cells.empty()) {
    cells.clear();
    for (const EnvMapCellInput& c : options.cells) {
      CellRef ref{c.region, &c.visible, 0, 0};
      if (const auto it = problem_by_corner.find({c.region.lo.x, c.region.lo.y, c.region.lo.z});
          it != problem_by_corner.end()) {
        ref.cpv_first = index.nodes[it->second].cpv_first;
        ref.cpv_count = index.nodes[it->second].cpv_count;
      }
      for (uint32_t id : c.visible)
        if (id == 0 || id > scene.objects.size())
          throw Error("environment-map cells", "object id " + std::to_string(id) + " is not in the scene");
      cells.push_back(ref);
    }
  }
  report.all_cells = cells.size();
  if (options.sample > 0 && options.sample < cells.size()) {
    std::mt19937 rng(options.seed);
    std::shuffle(cells.begin(), cells.end(), rng);
    cells.resize(options.sample);
  }

  context.makeCurrent();
  const gpu::GpuScene gpu_scene(scene);
  gpu::Renderer renderer;
  const scene::Bvh bvh(scene);
  const std::vector<gpu::ObjectDrawCost> cost = gpu_scene.objectDrawCosts();
  std::vector<double> distances = options.far_distances;
  std::sort(distances.begin(), distances.end(), std::greater<>());
  const double pixels = double(bound.width) * double(bound.height);
  const FillLens fill_lens = FillLens::of(bound.width, bound.height, bound.fov_y);

  std::unique_ptr<Progress> progress;
  if (options.progress) progress = std::make_unique<Progress>("envmap baseline", cells.size());
  std::vector<uint32_t> in_frustum;
  for (const CellRef& node : cells) {
    EnvMapCell cell;
    cell.region = node.box;
    cell.cpvs = node.cpv_count;
    cell.visible_objects = node.visible->size();
    std::vector<impostor::EnvMapObject> objects;
    for (uint32_t id : *node.visible) objects.push_back({id, scene.objects[id - 1].world_bounds});

    // The largest distance that keeps every CPV of the cell under t_max.
    impostor::EnvMapPlan plan;
    bool have = false;
    const double radius = 0.5 * double(glm::length(node.box.extent()));
    for (double d : distances) {
      if (d <= radius * 1.01) continue;
      impostor::EnvMapPlan candidate = impostor::planEnvironmentMap(node.box, d, objects, bound, options.envmap);
      double worst = 0.0;
      for (uint32_t k = node.cpv_first; k < node.cpv_first + node.cpv_count; ++k) {
        in_frustum.clear();
        const Frustum frustum = enclosingFrustum(node.box, index.cpvs[k].vdi, lens);
        bvh.queryFrustum(frustum, in_frustum);
        std::sort(in_frustum.begin(), in_frustum.end());
        uint64_t triangles = 2 * candidate.layers(), draws = candidate.draws();
        double fill = 0.0;  // of the near geometry, as placement charges it
        for (uint32_t id : candidate.near_objects)
          if (std::binary_search(in_frustum.begin(), in_frustum.end(), id)) {
            triangles += cost[id].triangles;
            draws += cost[id].draws;
            fill += fill_lens.objectPixels(scene.objects[id - 1].world_bounds, node.box);
          }
        // The layers the CPV's frustum meets fill the frame through the alpha test, charged as placement charges its
        // impostors' layers (the profile's layered draw term; 0 for a profile without it).
        const impostor::EnvMapLayersInView layers = impostor::envMapLayersInView(candidate, frustum, bound);
        worst = std::max(worst, profile.boundMs(double(triangles), double(draws), pixels, fill) +
                                    profile.layered.drawBoundMs(double(layers.quads), layers.fill_pixels));
      }
      const bool fits = worst <= t_max_ms;
      if (fits || !have || d < plan.far_distance) {
        plan = std::move(candidate);
        cell.t_est_max_ms = worst;
        cell.solved = fits;
        have = true;
      }
      if (fits) break;
    }
    if (!have)
      throw Error("--far", "no distance is beyond the cell's half-diagonal " + std::to_string(radius) + " m");
    report.unsolved += cell.solved ? 0 : 1;
    cell.far_distance = plan.far_distance;
    cell.near_objects = plan.near_objects.size();
    cell.far_objects = cell.visible_objects - cell.near_objects;
    cell.faces = plan.faces.size();
    cell.planned_bytes = plan.bytes();

    Stopwatch capture;
    for (const impostor::EnvMapFace& face : plan.faces) {
      const impostor::LayeredPlan cropped = captureFace(renderer, gpu_scene, scene, face, &cell.covered_texels);
      cell.layers += cropped.layers.size();
      cell.draws += cropped.draws();
      cell.bytes += cropped.bytes();
      cell.stored_texels += cropped.texels;
    }
    cell.capture_s = capture.seconds();
    report.bytes_captured += double(cell.bytes);
    report.cells.push_back(cell);
    if (progress) progress->advance();
  }
  if (progress) progress->finish();

  const size_t m = report.cells.size();
  if (m > 0) {
    const double mean = report.bytes_captured / double(m);
    report.bytes_estimate = mean * double(report.all_cells);
    if (m < report.all_cells && m > 1) {
      double var = 0.0;
      for (const EnvMapCell& c : report.cells) var += (double(c.bytes) - mean) * (double(c.bytes) - mean);
      var /= double(m - 1);
      // Sampling without replacement: the finite-population correction.
      const double fpc = double(report.all_cells - m) / double(report.all_cells - 1);
      report.bytes_stderr = double(report.all_cells) * std::sqrt(var / double(m) * fpc);
    }
  }
  report.wall_s = wall.seconds();
  return report;
}

}  // namespace farfield::eval
