// farfield envmap-baseline SCENE --placement DIR --profile profile.json -o report.json [--sample N] [--seed S]
//                          [--far 50,100,...] [--all-cells VISIBILITY_CACHE]
// The per-cell environment-map baseline (Jeschke et al. 2005, test 15) for the view cells of a placement, at its
// t_max, error bound and frame: eval/envmap_baseline.h.
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>

#include "cli_util.h"
#include "command.h"
#include "farfield/bake/place.h"
#include "farfield/core/error.h"
#include "farfield/eval/envmap_baseline.h"
#include "farfield/gpu/context.h"
#include "farfield/scene/import.h"
#include "farfield/store/impostor_store.h"
#include "farfield/store/placement_store.h"

namespace farfield::app {
namespace {

struct EnvMapArgs {
  std::string scene, placement, profile, output, all_cells;
  std::vector<double> far;
  eval::EnvMapBaselineOptions options;
};

// Every cell of the view space from the visibility cache `farfield place --visibility-cache` wrote (each region's lower
// corner and visible set); the cells have the size of the placement's problem cells (all minimum-size regions of its
// partition have one size).
std::vector<eval::EnvMapCellInput> cellsFromCache(const std::string& path, const store::PlacementIndex& index) {
  std::ifstream in(path);
  if (!in) throw Error(path, "cannot be read");
  nlohmann::json j;
  try {
    in >> j;
  } catch (const std::exception& e) {
    throw Error(path, std::string("not JSON: ") + e.what());
  }
  Vec3 extent(0.0f);
  for (const store::StoredViewSpaceNode& n : index.nodes)
    if (n.children[0] == -1 && n.cpv_count > 0) extent = n.box.extent();
  if (extent == Vec3(0.0f)) throw Error("placement database", "has no problem cell");
  std::vector<eval::EnvMapCellInput> cells;
  try {
    for (const nlohmann::json& r : j.at("regions")) {
      eval::EnvMapCellInput c;
      c.region.lo = Vec3(r.at("lo")[0].get<float>(), r.at("lo")[1].get<float>(), r.at("lo")[2].get<float>());
      c.region.hi = c.region.lo + extent;
      c.visible = r.at("visible").get<std::vector<uint32_t>>();
      if (!index.view_space.contains(c.region.lo)) throw Error(path, "a region lies outside the placement's view space");
      cells.push_back(std::move(c));
    }
  } catch (const nlohmann::json::exception& e) {
    throw Error(path, std::string("not a visibility cache: ") + e.what());
  }
  if (cells.empty()) throw Error(path, "holds no region");
  return cells;
}

void runEnvMapBaseline(EnvMapArgs& args) {
  const store::PlacementIndex index = store::readPlacementIndex(args.placement);
  if (!args.all_cells.empty()) args.options.cells = cellsFromCache(args.all_cells, index);
  const bake::PlaceOptions place = bake::placeOptionsFromJson(index.options, args.placement + "/placement.json options");
  const ErrorBound bound{place.error_px, place.width, place.height, degToRad(double(place.fov_deg))};
  Lens lens;
  lens.fov_y = float(degToRad(double(place.fov_deg)));
  lens.aspect = float(place.width) / float(place.height);
  lens.near_plane = place.near_plane;
  lens.far_plane = place.far_plane;
  if (!args.far.empty()) args.options.far_distances = args.far;
  args.options.envmap.texel_pixels = place.layered.texel_pixels;
  args.options.envmap.max_texture_size = place.layered.max_texture_size;
  args.options.envmap.dilate_texels = place.layered.dilate_texels;
  const gpu::CostProfile profile = gpu::loadCostProfile(args.profile);
  const scene::Scene scene = scene::loadScene(args.scene);
  const eval::EnvMapBaselineReport r = eval::runEnvMapBaseline(gpu::sharedHeadlessContext(), scene, profile, index,
                                                               bound, lens, place.t_max_ms, args.options);
  ensureParentDirectory(args.output);
  store::writeFileAtomic(args.output, r.toJson().dump(1) + "\n");
  const double mb = 1.0 / (1024.0 * 1024.0);
  std::printf("envmap baseline: %zu of %zu problem cells captured, %zu unsolved at t_max %.1f ms\n", r.cells.size(),
              r.problem_cells, r.unsolved, r.t_max_ms);
  std::printf("memory: %.2f MB captured; all cells %.2f MB (+- %.2f); placement %.2f MB colour (%.2f as placed); "
              "ratio %.1fx\n",
              r.bytes_captured * mb, r.bytes_estimate * mb, r.bytes_stderr * mb, r.placement_bytes * mb,
              r.placement_total_bytes * mb, r.placement_bytes > 0.0 ? r.bytes_estimate / r.placement_bytes : 0.0);
  std::printf("wrote %s (%.1f s)\n", args.output.c_str(), r.wall_s);
}

const RegisterCommand reg("envmap-baseline", [](CLI::App& app) {
  auto args = std::make_shared<EnvMapArgs>();
  auto* cmd = app.add_subcommand(
      "envmap-baseline",
      "Per-cell layered environment maps (Jeschke et al. 2005, test 15) for the problem cells of a placement, at its "
      "t_max, bound and frame: their memory against the placement's.");
  cmd->add_option("scene", args->scene, "Scene the placement was made for")->required();
  cmd->add_option("--placement", args->placement, "Placement database (farfield place -o DIR)")->required();
  cmd->add_option("--profile", args->profile, "Cost profile (farfield calibrate)")->required();
  cmd->add_option("-o,--output", args->output, "Report to write (JSON)")->required();
  cmd->add_option("--sample", args->options.sample, "Cells to capture, chosen at random (0 = all)")
      ->capture_default_str();
  cmd->add_option("--seed", args->options.seed, "Seed of the sample")->capture_default_str();
  cmd->add_option("--far", args->far, "Far-field distances to try, metres (default 50,75,100,150,200,300,400,600)")
      ->delimiter(',');
  cmd->add_option("--all-cells", args->all_cells, "Every cell of the view space, from the visibility cache of the "
                                                  "placement (farfield place --visibility-cache), not only its "
                                                  "problem cells (the paper's rule; use one --far distance)");
  cmd->callback([args] { runEnvMapBaseline(*args); });
});

}  // namespace
}  // namespace farfield::app
