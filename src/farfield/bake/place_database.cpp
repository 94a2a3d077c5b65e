// The placement database's index: the problem view space with the regions' visible sets, the impostors shown
// somewhere and every CPV's times and impostors; the impostors' files are written already (place_passes.cpp).
#include <algorithm>
#include <cstdint>
#include <utility>

#include "farfield/bake/place_steps.h"
#include "farfield/core/timer.h"
#include "farfield/store/placement_store.h"

namespace farfield::bake {

void PlacedImpostors::writeDatabase(const scene::Scene& scene, const Box3& space,
                                    const placement::ViewSpace& view_space, const VisibleSets& region_visible,
                                    const PlaceOptions& options, const std::string& out_dir,
                                    PlaceReport& report) const {
  Stopwatch step;
  store::PlacementIndex index;
  index.generation = generation;
  index.scene = options.scene_label;
  index.scene_objects = scene.objects.size();
  index.options = placeOptionsToJson(options);
  index.view_space = space;
  for (const placement::ViewSpaceNode& n : view_space.nodes) {
    store::StoredViewSpaceNode s;
    s.box = n.box;
    s.children[0] = n.children[0];
    s.children[1] = n.children[1];
    s.cpv_first = n.cpv_first;
    s.cpv_count = n.cpv_count;
    if (n.children[0] < 0) {
      const auto it = region_visible.find({n.box.lo.x, n.box.lo.y, n.box.lo.z});
      if (it != region_visible.end() && !it->second.empty()) {
        s.has_visible = true;
        s.visible = it->second;
      }
    }
    index.nodes.push_back(s);
  }
  for (const auto& [id, n] : uses) {  // ascending ids, as the index lists them
    if (n == 0) continue;
    index.impostors.push_back(written.at(id));
    const impostor::LayeredPlan& plan = chosen_plans.at(id);
    report.layer_texels += plan.texels;
    for (const store::StoredImpostorLayer& layer : written.at(id).layers) {
      report.stored_texels += uint64_t(layer.crop.width) * uint64_t(layer.crop.height);
      report.covered_texels += layer.data_texels;
    }
    report.id_texture_bytes += id_bytes.at(id);
    report.estimated_bytes += double(plan.bytes());
    report.memory_bytes += double(written.at(id).bytes);
    ++report.impostors;
  }
  for (size_t c = 0; c < view_space.cpvs.size(); ++c) {
    store::StoredCpv s;
    s.region = view_space.cpvs[c].region;
    s.vdi = view_space.cpvs[c].vdi;
    s.t_enc = view_space.cpvs[c].t_enc;
    s.t_after = cpv_t[c];
    for (const auto& [id, node] : cpv_shown[c]) s.impostors.push_back(id);
    std::sort(s.impostors.begin(), s.impostors.end());
    if (s.t_after > options.t_max_ms) ++report.unsolved_cpvs;
    report.t_after_max_ms = std::max(report.t_after_max_ms, s.t_after);
    index.cpvs.push_back(std::move(s));
  }
  report.impostors_freed = report.impostors_generated - report.impostors;
  for (const store::StoredPlacedImpostor& imp : index.impostors)  // the data files (the index comes on top)
    for (const store::StoredImpostorLayer& l : imp.layers)
      report.written_bytes += l.texture_check.bytes + l.ids_check.bytes;
  index.summary = report.toJson();
  store::writePlacementIndex(out_dir, index);
  // writePlacementIndex removed the files of the impostors the greedy freed (no longer named by the index).
  report.written_bytes = store::placementBytes(out_dir, index);
  report.write_s = step.seconds();
}

}  // namespace farfield::bake
