// farfield place SCENE --profile profile.json -o DIR [--tmax MS] [--error-px PX] [--size WxH] [--fov DEG]
//                [--view-min X,Y,Z --view-max X,Y,Z] [--cpv-size M] [--vdi-deg DEG] [--levels N] ...
// farfield place SCENE --visibility-only --visibility-cache vis.json [--cpv-size M] [view space options]
// Automatic impostor placement (Jeschke et al. 2005; bake/place.h): which object clusters become layered impostors
// for which view cells, so every view of the view space renders under t_max with an error under the bound.
#include <cmath>
#include <cstdio>
#include <memory>

#include "cli_util.h"
#include "command.h"
#include "farfield/bake/place.h"
#include "farfield/core/error.h"
#include "farfield/gpu/context.h"
#include "farfield/scene/import.h"

namespace farfield::app {
namespace {

struct PlaceArgs {
  std::string scene;
  std::string profile;
  std::string out;
  std::string size = "512x512";
  std::string view_min, view_max, around;
  float margin = 50.0f;
  int distance_steps = 11;
  std::string view_cells = "shafts";
  double texel_px = 0.0;
  bake::PlaceOptions options;
};

void runPlaceCommand(PlaceArgs& args) {
  bake::PlaceOptions& o = args.options;
  const IVec2 size = parseSize("--size", args.size);
  o.width = size.x;
  o.height = size.y;
  o.view_space = parseViewSpace(args.view_min, args.view_max, args.around, args.margin);
  if (args.distance_steps < 1) throw Error("--distance-steps", "must be at least 1");
  o.candidates.distance_steps = args.distance_steps;
  if (args.view_cells != "shafts" && args.view_cells != "boxes" && args.view_cells != "leaf-boxes" &&
      args.view_cells != "both" && args.view_cells != "none")
    throw Error("--view-cells", "'" + args.view_cells + "' is not shafts, boxes, leaf-boxes, both or none");
  o.candidates.shafts = args.view_cells == "shafts" || args.view_cells == "both";
  o.candidates.rectangular_cells = args.view_cells != "shafts" && args.view_cells != "none";
  o.candidates.box_leaves_only = args.view_cells == "leaf-boxes";
  o.scene_label = args.scene;
  if (args.texel_px < 0.0) throw Error("--texel-px", "must be 0 (the error bound) or a positive number of pixels");
  o.layered.texel_pixels = args.texel_px > 0.0 ? args.texel_px : o.error_px;
  if (!o.visibility_only && args.profile.empty()) throw Error("--profile", "is required (unless --visibility-only)");
  if (!o.visibility_only && args.out.empty()) throw Error("-o", "is required (unless --visibility-only)");
  const gpu::CostProfile profile = o.visibility_only ? gpu::CostProfile{} : gpu::loadCostProfile(args.profile);
  const scene::Scene scene = scene::loadScene(args.scene);
  const bake::PlaceReport r = bake::placeImpostors(gpu::sharedHeadlessContext(), scene, profile, o, args.out);
  if (o.visibility_only) {
    std::printf("visibility:       %zu regions (%zu from the cache) sampled from %zu points, %.1f objects seen per "
                "region, %.1f s\n",
                r.visibility_regions, r.visibility_cached, r.visibility_points, r.mean_visible_objects,
                r.visibility_s);
    std::printf("cache:            %s\n", o.visibility_cache.c_str());
    return;
  }
  std::printf("scene:            %s (%zu objects: %zu clustered, %zu always geometry)\n", args.scene.c_str(),
              scene.objects.size(), r.clustered_objects, r.geometry_objects);
  char margin[64] = "";
  if (std::isfinite(profile.safety_margin_ms))
    std::snprintf(margin, sizeof margin, ", or + %.2f ms where smaller", profile.safety_margin_ms);
  std::printf("promises:         t_max %.2f ms, error %.2f px at %dx%d, %.1f deg (profile %s: bound prediction x "
              "%.3f%s; at t_max a factor of %.3f)\n",
              o.t_max_ms, o.error_px, o.width, o.height, double(o.fov_deg), args.profile.c_str(),
              profile.safety_factor, margin, r.safety_factor);
  if (o.visibility)
    std::printf("visibility:       %zu regions (%zu from the cache) sampled from %zu points, %.1f objects seen per "
                "region, %.1f s\n",
                r.visibility_regions, r.visibility_cached, r.visibility_points, r.mean_visible_objects,
                r.visibility_s);
  std::printf("view space:       %zu regions visited, %zu with problem views, %zu CPVs (%zu estimates), %.1f s\n",
              r.regions, r.problem_regions, r.cpvs, r.estimates, r.view_space_s);
  std::printf("candidates:       %zu considered, %zu intersecting, %zu serving no CPV, %zu identical, %zu kept, "
              "%zu without a plan under the bound, %zu CPV serves dropped, %.1f s\n",
              r.candidate_counts.considered, r.candidate_counts.intersecting, r.candidate_counts.no_cpv,
              r.candidate_counts.identical, r.candidate_counts.kept, r.candidates_unplannable, r.serves_dropped,
              r.candidates_s);
  std::printf("greedy:           %zu generated, %zu kept, %zu freed; %.1f s choosing, %.1f s capturing\n",
              r.impostors_generated, r.impostors, r.impostors_freed, r.greedy_s, r.capture_s);
  std::printf("CPVs:             slowest %.2f ms before, %.2f ms after; %zu unsolved (still over t_max)\n",
              r.t_enc_max_ms, r.t_after_max_ms, r.unsolved_cpvs);
  std::printf("cost model:       layered fill %s\n",
              r.layered_fill_in_model ? "in the impostors' times (profile's layered terms)"
                                      : "NOT in the impostors' times (profile without layered terms)");
  if (!o.fallback_bound_factors.empty())
    std::printf("fallback:         %zu CPVs over t_max at the bound; coarser passes kept %zu impostors shown in %zu "
                "(CPV, impostor) pairs; %zu CPVs left over t_max\n",
                r.unsolved_at_bound, r.fallback_impostors, r.fallback_cpv_impostors, r.unsolved_cpvs);
  std::printf("memory:           %.2f MB of impostors (GPU), %.2f MB on disk\n", r.memory_bytes / 1048576.0,
              double(r.written_bytes) / 1048576.0);
  std::printf("                  of which %.2f MB object-id textures (for measurement); layers cropped to their "
              "data: %.1f%% of the captured texels kept (%.2f MB estimated before), %.1f%% of those covered\n",
              r.id_texture_bytes / 1048576.0,
              r.layer_texels ? 100.0 * double(r.stored_texels) / double(r.layer_texels) : 0.0,
              r.estimated_bytes / 1048576.0,
              r.stored_texels ? 100.0 * double(r.covered_texels) / double(r.stored_texels) : 0.0);
  std::printf("wall:             %.1f s\n", r.wall_s);
  std::printf("database:         %s\n", args.out.c_str());
}

const RegisterCommand reg("place", [](CLI::App& app) {
  auto args = std::make_shared<PlaceArgs>();
  bake::PlaceOptions& o = args->options;
  auto* cmd = app.add_subcommand("place", "Automatic impostor placement (Jeschke 2005): layered impostors of object "
                                          "clusters per view cell, keeping every view under t_max and the error bound");
  cmd->add_option("scene", args->scene, "Scene file (glTF, OBJ, ...) or builtin:NAME")->required();
  cmd->add_option("--profile", args->profile, "Cost profile of this machine (farfield calibrate -o FILE)");
  cmd->add_option("-o,--out", args->out, "Placement database directory to write");
  cmd->add_option("--tmax", o.t_max_ms, "Frame budget, ms")->capture_default_str();
  cmd->add_option("--error-px", o.error_px, "Error bound, pixels of the frames")->capture_default_str();
  cmd->add_option("--size", args->size, "Frame size WxH")->capture_default_str();
  cmd->add_option("--fov", o.fov_deg, "Vertical field of view, degrees")->capture_default_str();
  cmd->add_option("--view-min", args->view_min, "View space corner X,Y,Z (default: the scene's bounds at 1.2-1.7 m)");
  cmd->add_option("--view-max", args->view_max, "View space corner X,Y,Z");
  cmd->add_option("--around", args->around, "View space: the district along a camera path (its eyes' bounds "
                                           "grown by --margin)");
  cmd->add_option("--margin", args->margin, "Margin of --around on the ground, metres")->capture_default_str();
  cmd->add_option("--cpv-size", o.min_region_size, "Side of the CPVs' regions, metres")->capture_default_str();
  cmd->add_option("--vdi-deg", o.min_vdi_deg, "Width of the CPVs' view-direction intervals, degrees")
      ->capture_default_str();
  cmd->add_option("--max-pitch", o.max_pitch_deg, "Views pitched further from the horizon are not guarded, degrees "
                                                  "(90: all)")->capture_default_str();
  cmd->add_flag("!--no-visibility", o.visibility, "Count every object in a view's frustum (no from-region "
                                                 "visibility)");
  cmd->add_option("--visibility-cache", o.visibility_cache, "Keep the sampled visible sets in this file between runs "
                                                            "(a t_max sweep samples them once)");
  cmd->add_flag("--visibility-only", o.visibility_only, "Sample every region's visible set into --visibility-cache "
                                                        "and stop (for calibrate --visibility-cache)");
  cmd->add_option("--visibility-face", o.visibility_face, "Item-buffer face size of the visibility samples, pixels")
      ->capture_default_str();
  cmd->add_option("--visibility-grid", o.visibility_grid, "Visibility sample points per side of a region (N x N at "
                                                          "mid height; 2: the corners and the centre)")
      ->capture_default_str();
  cmd->add_option("--levels", o.hierarchy.max_levels, "Levels of the object hierarchy")->capture_default_str();
  cmd->add_option("--distance-steps", args->distance_steps, "Shaft minimum distances per axis (1, 2, 4, ... times "
                                                             "the cluster size)")->capture_default_str();
  cmd->add_option("--view-cells", args->view_cells, "Candidate view cells: shafts (the paper's), boxes (the view "
                                                     "space's regions, each planned through the shaft around it: the "
                                                     "paper's test 13), leaf-boxes (the smallest regions only: "
                                                     "per-cell placement, test 14), both, or none (no "
                                                     "impostor: the problem view space and its regions' visible sets "
                                                     "alone, a control for what the impostors add)")
      ->capture_default_str();
  cmd->add_option("--max-texture", o.layered.max_texture_size, "Largest layer texture side, texels")
      ->capture_default_str();
  cmd->add_option("--texel-px", args->texel_px, "Impostor texel size in pixels of the frames at the nearest "
                                                 "viewpoint (0: the error bound)")->capture_default_str();
  cmd->add_option("--fallback-bounds", o.fallback_bound_factors,
                  "For CPVs left over t_max: more greedy passes with impostors under the bound times each factor "
                  "(e.g. 2,4; each > 1); default none")
      ->delimiter(',');
  cmd->add_flag("--bound-cracks", o.layered.bound_cracks, "Halve layer spacing so cracks also stay under the bound");
  cmd->add_flag("!--no-layer-tiles", o.layer_tiles, "Charge the layers' fill over their whole quads, as placement did "
                                                   "before layers were drawn as their tiles (for comparisons)");
  cmd->add_flag("!--no-id-textures", o.layered.id_textures, "Leave out the per-texel object ids (half the impostors' "
                                                             "memory; bench then cannot measure their parallax)");
  cmd->callback([args] { runPlaceCommand(*args); });
});

}  // namespace
}  // namespace farfield::app
