// farfield crowd bench -o OUTDIR [--agents 1000,10000] [--paths pedestrian,elevated] [--frames N] [--step K]
//                      [--size WxH] [--blocks N] [--detail D] [--models A.glb,B.glb] [--texel M] [--cycle-frames F]
//                      [--azimuths A] [--elevations E] [--octahedral N] [--error-px PX] [--atlas-from-bound] [--bound-switch M]
//                      [--blend-views] [--outfits N] [--no-shadows] [--shadow-map N] [--shadow-distance M]
//                      [--agent-occlusion] [--impostor-shadows]
// Animated crowds with multi-view impostors on a generated city: eval::runCrowdBench (eval/crowd_bench.h). Without
// --models the crowd is the built-in figures (eval::builtinCrowdModels).
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "cli_util.h"
#include "command.h"
#include "farfield/core/allocator.h"
#include "farfield/core/error.h"
#include "farfield/eval/crowd_bench.h"
#include "farfield/gpu/context.h"
#include "farfield/impostor/multi_view.h"

namespace farfield::app {
namespace {

struct CrowdArgs {
  eval::CrowdBenchOptions o;
  std::string agents = "1000,10000";
  std::string paths = "pedestrian,elevated";
  std::string size = "512x512";
  std::string models;  // empty: the built-in figures
  int octahedral = 0;
  bool palette_skinning = false;
};

void run(CrowdArgs& a) {
  configureTimingAllocator();
  const IVec2 size = parseSize("--size", a.size);
  a.o.width = size.x;
  a.o.height = size.y;
  a.o.agent_counts.clear();
  for (const std::string& s : splitList(a.agents)) {
    try {
      size_t used = 0;
      const long long v = std::stoll(s, &used);
      if (used != s.size() || v < 1) throw std::invalid_argument(s);
      a.o.agent_counts.push_back(size_t(v));
    } catch (const std::exception&) {
      throw Error("--agents", "expected a comma-separated list of positive counts, got '" + a.agents + "'");
    }
  }
  a.o.paths = splitList(a.paths);
  if (a.o.outfits < 1) throw Error("--outfits", "must be at least 1");
  if (a.o.shadow.map_size < 16 || !(a.o.shadow.distance_m > 0.0f))
    throw Error("--shadow-map/--shadow-distance", "must be at least 16 texels and a positive distance");
  a.o.models = splitList(a.models);
  if (a.o.runtime.grid.azimuths < 1 || a.o.runtime.grid.elevations < 1)
    throw Error("--azimuths/--elevations", "must be at least 1");
  if (a.octahedral == 1 || a.octahedral < 0) throw Error("--octahedral", "must be 0 (off) or at least 2 views a side");
  if (a.palette_skinning && a.o.compare_skinning)
    throw Error("--compare-skinning", "compares the palette with the baked poses: leave out --palette-skinning");
  if (a.palette_skinning) a.o.runtime.skinning = gpu::Skinning::Palette;
  if (a.octahedral >= 2) a.o.runtime.grid = impostor::ViewGrid::octahedralGrid(a.octahedral);
  if (a.o.runtime.budget_coarsens &&
      ((a.o.runtime.max_geometry_triangles == 0 && !(a.o.runtime.geometry_ms > 0.0)) ||
       !(a.o.runtime.geometry_lod_px > 0.0)))
    throw Error("--budget-coarsens",
                "needs a budget (--geometry-triangles or --geometry-ms) and levels of detail (--skinned-lod)");
  const eval::CrowdBenchResult r = eval::runCrowdBench(gpu::sharedHeadlessContext(), a.o);
  std::printf("%s\nwrote %s/{crowd.json,crowd.md,frames/}\n", r.markdown.c_str(), a.o.out_dir.c_str());
}

const RegisterCommand reg("crowd", [](CLI::App& app) {
  auto* cmd = app.add_subcommand("crowd", "Animated crowds with precomputed multi-view impostors");
  cmd->require_subcommand(1);
  auto a = std::make_shared<CrowdArgs>();
  eval::CrowdBenchOptions& o = a->o;
  auto* bench = cmd->add_subcommand("bench", "crowd-geometry, crowd-impostor and crowd-mixed on a generated city "
                                             "against full-geometry reference frames");
  bench->add_option("-o,--out", o.out_dir, "Output directory")->required();
  bench->add_option("--agents", a->agents, "Crowd sizes, comma-separated")->capture_default_str();
  bench->add_option("--paths", a->paths, "Camera paths: pedestrian, elevated")->capture_default_str();
  bench->add_option("--frames", o.frames, "Measured frames per run")->capture_default_str();
  bench->add_option("--step", o.frame_step, "Path frames between measured frames (30 fps)")->capture_default_str();
  bench->add_option("--size", a->size, "Frame size WxH")->capture_default_str();
  bench->add_option("--blocks", o.blocks, "City blocks")->capture_default_str();
  bench->add_option("--detail", o.detail, "City facade detail 0..4")->capture_default_str();
  bench->add_option("--city-seed", o.city_seed, "City seed")->capture_default_str();
  bench->add_option("--crowd-seed", o.crowd_seed, "Crowd seed")->capture_default_str();
  bench->add_option("--path-seed", o.path_seed, "Street walk seed")->capture_default_str();
  bench->add_option("--models", a->models,
                    "Skinned glTF models, comma-separated (first two: heights 1.75, 0.8 m, as the shared CesiumMan "
                    "and Fox); default: the built-in figures, a walker and a four-legged one, no file read");
  bench->add_option("--texel", o.runtime.texel_m, "Atlas texel size, metres")->capture_default_str();
  bench->add_option("--cycle-frames", o.runtime.frames, "Impostor frames per walk cycle")->capture_default_str();
  bench->add_option("--azimuths", o.runtime.grid.azimuths, "Impostor views around")->capture_default_str();
  bench->add_option("--elevations", o.runtime.grid.elevations, "Impostor view elevations")->capture_default_str();
  bench->add_option("--octahedral", a->octahedral, "N > 1: views on an N x N octahedral map of the hemisphere "
                                                    "instead of azimuths x elevations (with --atlas-from-bound: the "
                                                    "octahedral grid the bound asks for)")
      ->capture_default_str();
  bench->add_option("--error-px", o.runtime.error_px, "View error bound (pixels) of crowd-mixed")->capture_default_str();
  bench->add_option("--geometry-triangles", o.runtime.max_geometry_triangles,
                    "crowd-mixed's geometry budget: skinned triangles a frame for the nearest agents inside their "
                    "switch distance, the others as impostors (0: none)")
      ->capture_default_str();
  bench->add_option("--geometry-ms", o.runtime.geometry_ms,
                    "crowd-mixed's geometry budget in milliseconds of skinned drawing a frame, from the measured time "
                    "per triangle (0: none; with --geometry-triangles the smaller holds)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  bench->add_flag("--budget-coarsens", o.runtime.budget_coarsens,
                  "Under --geometry-triangles, agents also take coarser levels of detail (--skinned-lod), the least "
                  "error on screen first, before impostors");
  bench->add_flag(
      "--palette-skinning", a->palette_skinning,
      "Skinned agents blend four joint matrices of their palette pose per vertex instead of reading the pose's "
      "vertices skinned once at start-up (the same images; for comparing the two)");
  bench->add_option("--repeats", o.timing_passes,
                    "Timing passes over the frames; each frame's fastest render is kept (the images are the first "
                    "pass's)")
      ->capture_default_str()
      ->check(CLI::Range(1, 100));
  bench->add_flag("--compare-skinning", o.compare_skinning,
                  "Also crowd-geometry-palette and crowd-mixed-palette: the same policies with joint matrices blended "
                  "per vertex, timed on the same frames");
  bench->add_flag("--gpu-crowd", o.gpu_crowd,
                  "Also crowd-geometry-gpu, crowd-impostor-gpu and crowd-mixed-gpu: the crowd simulated, culled, "
                  "classified, drawn and shadowed on the GPU (--geometry-triangles, --geometry-ms, --skinned-lod and "
                  "--blend-views hold there; --budget-coarsens not yet)");
  bench->add_flag("--city-cpu", o.city_cpu,
                  "The city under the crowd culled on the CPU with its occluders' depth read back (the culled-cpu "
                  "mode) instead of the GPU-driven frame (the culled mode; no wait in the frame)");
  bench->add_option("--skinned-lod", o.runtime.geometry_lod_px,
                    "crowd-mixed's skinned agents at the coarsest level of detail within this many pixels "
                    "(0: the mesh)")
      ->capture_default_str();
  bench->add_flag("!--lod-distance-only", o.runtime.lod_texture,
                  "A level's error for --skinned-lod is its distance to the mesh alone, not the larger of that and "
                  "how far it moves a texel (its texture deviation)");
  bench->add_option("--skinned-lod-ratios", o.runtime.lod_ratios,
                    "The levels' triangles as fractions of the mesh's, decreasing, comma-separated")
      ->delimiter(',')
      ->capture_default_str();
  bench->add_option("--samples", o.samples, "Sample frames saved per run")->capture_default_str();
  bench->add_flag("--atlas-from-bound", o.runtime.atlas_from_bound,
                  "Choose views, frames and texel per model from --error-px for impostors from --bound-switch on");
  bench->add_option("--bound-switch", o.runtime.bound_switch_m, "Distance (m) from which the bound's atlas holds")
      ->capture_default_str();
  bench->add_flag("--blend-views", o.runtime.blend_views, "Impostors blend the four views around the eye direction");
  bench->add_option("--outfits", o.outfits, "Colour-region outfits (16 region tints each)")->capture_default_str();
  bench->add_flag("!--no-shadows", o.shadows, "No agent shadows");
  bench->add_flag("--agent-occlusion", o.agent_occlusion,
                  "Every mode leaves out the agents hidden behind the city (exact; the reference never culls)");
  bench->add_flag("--impostor-shadows", o.impostor_shadows,
                  "crowd-mixed's geometry agents cast their shadows as impostors (the reference's cast geometry)");
  bench->add_option("--shadow-map", o.shadow.map_size, "Shadow map texels per side")->capture_default_str();
  bench->add_option("--shadow-distance", o.shadow.distance_m, "Shadow receivers up to this distance (m)")
      ->capture_default_str();
  bench->callback([a] { run(*a); });
});

}  // namespace
}  // namespace farfield::app
