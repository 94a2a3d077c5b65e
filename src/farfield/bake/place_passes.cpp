// The layered impostors chosen: candidates with their layered plans, the greedy over them with lazy recalculation,
// and each chosen impostor captured on the GPU and written at once; at the bound, then per fallback bound.
#include <algorithm>
#include <filesystem>
#include <map>
#include <optional>
#include <utility>
#include <vector>

#include "farfield/bake/place_steps.h"
#include "farfield/core/error.h"
#include "farfield/core/log.h"
#include "farfield/core/timer.h"
#include "farfield/impostor/layered.h"
#include "farfield/placement/greedy.h"
#include "farfield/placement/placement_problem.h"
#include "farfield/store/placement_store.h"

namespace fs = std::filesystem;

namespace farfield::bake {

void PlacedImpostors::placeInPasses(const scene::Scene& scene, const gpu::GpuScene& gpu_scene,
                                    gpu::Renderer& renderer, const placement::ObjectHierarchy& hierarchy,
                                    const placement::ViewSpace& view_space, const placement::CandidateSet& all,
                                    const ErrorBound& bound, PlaceEstimates& est, const PlaceOptions& options,
                                    const std::string& out_dir, PlaceReport& report) {
  const std::vector<int> parents = hierarchy.parents();
  const auto related = [&](int a, int b) {
    for (int at = a; at >= 0; at = parents[size_t(at)])
      if (at == b) return true;
    for (int at = b; at >= 0; at = parents[size_t(at)])
      if (at == a) return true;
    return false;
  };
  fs::create_directories(out_dir);
  generation = store::nextPlacementGeneration(out_dir);
  for (const placement::Cpv& c : view_space.cpvs) cpv_t.push_back(c.t_enc);
  cpv_shown.resize(view_space.cpvs.size());
  uint32_t next_id = 0;
  double capture_s = 0.0, greedy_total_s = 0.0;
  std::vector<double> factors{1.0};
  for (double f : options.fallback_bound_factors) factors.push_back(f);
  for (size_t pass = 0; pass < factors.size(); ++pass) {
    std::vector<uint8_t> open(view_space.cpvs.size(), 0);
    size_t open_count = 0;
    for (size_t c = 0; c < cpv_t.size(); ++c)
      if (cpv_t[c] > options.t_max_ms) open[c] = 1, ++open_count;
    if (pass == 1) report.unsolved_at_bound = open_count;
    if (open_count == 0) break;
    ErrorBound pass_bound = bound;
    pass_bound.pixels *= factors[pass];
    Stopwatch plan_clock;
    placement::CandidateSet kept;
    kept.counts = all.counts;
    std::vector<impostor::LayeredPlan> plans;
    std::vector<Box3> parts;  // the candidate's objects: each layer's cover planned from them
    for (const placement::Candidate& original : all.candidates) {
      const std::optional<Shaft> shaft = placement::planningShaft(original, hierarchy);
      if (!shaft) {
        if (pass == 0) ++report.candidates_unplannable;  // a box cell no shaft from the cluster's centre holds
        continue;
      }
      placement::Candidate c = original;
      // Later passes: only the CPVs still over t_max, and not where an impostor of a related node is shown already.
      if (pass > 0)
        c.cpvs.erase(std::remove_if(c.cpvs.begin(), c.cpvs.end(),
                                    [&](uint32_t cpv) {
                                      if (!open[cpv]) return true;
                                      for (const auto& [id, node] : cpv_shown[cpv])
                                        if (related(node, c.node)) return true;
                                      return false;
                                    }),
                     c.cpvs.end());
      if (c.cpvs.empty()) continue;
      try {
        parts.clear();
        if (options.layer_tiles)
          for (uint32_t id : hierarchy.objects(c.node)) parts.push_back(scene.objects[id - 1].world_bounds);
        impostor::LayeredPlan plan = impostor::planLayered(hierarchy.nodes()[size_t(c.node)].bounds, *shaft,
                                                           pass_bound, options.layered, parts);
        if (!plan.keepsBound()) {
          if (pass == 0) ++report.candidates_unplannable;
          continue;
        }
        // A CPV where the node's visible geometry costs no more than its impostor gains nothing from it.
        const size_t before = c.cpvs.size();
        c.cpvs.erase(std::remove_if(c.cpvs.begin(), c.cpvs.end(),
                                    [&](uint32_t cpv) { return est.tObject(c.node, cpv) <= est.tImpostor(plan, cpv); }),
                     c.cpvs.end());
        report.serves_dropped += before - c.cpvs.size();
        if (c.cpvs.empty()) continue;
        plans.push_back(std::move(plan));
        kept.candidates.push_back(std::move(c));
      } catch (const Error&) {
        if (pass == 0) ++report.candidates_unplannable;  // the shaft does not clear the cluster
      }
    }
    if (pass == 0) report.candidates_s += plan_clock.seconds();
    FF_INFO("place: pass at " << pass_bound.pixels << " px: " << kept.candidates.size()
                              << " candidates with a layered plan serve " << open_count << " CPVs over t_max");
    const placement::Candidate* first = kept.candidates.empty() ? nullptr : &kept.candidates.front();
    placement::PlacementEstimates estimates;
    estimates.t_object = [&](int node, uint32_t cpv) { return est.tObject(node, cpv); };
    estimates.t_impostor = [&](const placement::Candidate& c, uint32_t cpv) {
      return est.tImpostor(plans[size_t(&c - first)], cpv);
    };
    estimates.memory = [&](const placement::Candidate& c) { return double(plans[size_t(&c - first)].bytes()); };
    Stopwatch estimate_clock;
    placement::GreedyProblem problem = placement::makeGreedyProblem(view_space, hierarchy, kept, estimates);
    problem.cpv_times = cpv_t;
    report.estimates_s += estimate_clock.seconds();

    Stopwatch greedy_clock;
    std::map<size_t, uint32_t> id_of;  // candidate of this pass -> impostor id
    const double capture_before = capture_s;
    const placement::GreedyResult result = placement::placeGreedy(problem, [&](size_t k) {
      Stopwatch capture;
      const placement::Candidate& c = kept.candidates[k];
      std::vector<uint32_t> objects(hierarchy.objects(c.node).begin(), hierarchy.objects(c.node).end());
      std::sort(objects.begin(), objects.end());
      // Each layer keeps only the rectangle its slab's objects cover (cropLayered: the same image, fewer texels).
      const impostor::LayeredImpostor imp =
          impostor::cropLayered(impostor::captureLayered(renderer, gpu_scene, objects, plans[k]));
      const uint32_t id = next_id++;
      id_of[k] = id;
      written[id] = store::writePlacedImpostor(out_dir, generation, id, uint32_t(c.node), objects, imp,
                                               hierarchy.nodes()[size_t(c.node)].bounds, plans[k].shaft,
                                               pass_bound, options.layered);
      id_bytes[id] = imp.plan.id_textures ? 0.5 * double(imp.plan.texture_bytes) : 0.0;
      chosen_plans[id] = plans[k];
      capture_s += capture.seconds();
      ++report.impostors_generated;
      if (options.progress && report.impostors_generated % 25 == 0)
        FF_INFO("place: " << report.impostors_generated << " impostors generated");
      // Measured after generation (section 5.3): the memory of the cropped layers, and in each served CPV the time of
      // the quads as cropped (smaller than the plan's: fill falls with them), so a CPV's t_after is what the runtime
      // will draw, still bounded from the region's nearest point.
      placement::GeneratedImpostor made{double(imp.plan.bytes()), {}};
      made.t_impostor.reserve(c.cpvs.size());
      impostor::LayeredPlan charged = imp.plan;  // the cropped quads, over their tiles or (without) whole
      if (!options.layer_tiles) impostor::coverWholeQuads(charged);
      for (uint32_t cpv : c.cpvs) made.t_impostor.push_back(est.tImpostor(charged, cpv));
      return made;
    });
    greedy_total_s += greedy_clock.seconds() - (capture_s - capture_before);
    for (size_t c = 0; c < cpv_t.size(); ++c) {
      cpv_t[c] = result.cpv_times[c];
      for (uint32_t i : result.cpv_impostors[c]) {
        const uint32_t id = id_of.at(result.impostors[i].candidate);
        cpv_shown[c].push_back({id, kept.candidates[result.impostors[i].candidate].node});
        ++uses[id];
        if (pass > 0) ++report.fallback_cpv_impostors;
      }
    }
    if (pass > 0) report.fallback_impostors += result.impostors.size();
  }
  if (factors.size() == 1) report.unsolved_at_bound = 0;
  report.greedy_s = greedy_total_s;
  report.capture_s = capture_s;
}

}  // namespace farfield::bake
