// farfield envmap-baseline SCENE --placement DIR --profile profile.json -o report.json [--sample N] [--seed S]
//                          [--far 50,100,...]
// The per-cell environment-map baseline (Jeschke et al. 2005, test 15) for the view cells of a placement, at its
// t_max, error bound and frame: eval/envmap_baseline.h.
#include <cstdio>
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
  std::string scene, placement, profile, output;
  std::vector<double> far;
  eval::EnvMapBaselineOptions options;
};

void runEnvMapBaseline(EnvMapArgs& args) {
  const store::PlacementIndex index = store::readPlacementIndex(args.placement);
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
  cmd->callback([args] { runEnvMapBaseline(*args); });
});

}  // namespace
}  // namespace farfield::app
