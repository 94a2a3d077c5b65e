// farfield bake SCENE [--streets city.streets.json] [--local edge|junction] [--cell-lookup street|nearest]
//                (--pipeline pvs,near-far,single,mmi [--online mmi] | --technique depth-mesh|grid-mesh)
//                [--error-px 10] [--frame-size 640x360] [--frame-fov 60] [--station-spacing 5]
//                [--layer-mesh grid|depth-mesh] [--grid-cells 30] [--views street|six] [--pvs-spacing M]
//                [--pvs-face PX] [--pvs-no-occlusion] [--near-radius M] [--landmarks IDS] [--landmark-boost X]
//                [--resolution 512] [--fov DEG] [--eye-height M] [--path path.json]
//                [--cells E,E,...] [--limit N] [--workers N] [--list] [--shard K/N] [--resume] -o city.imp/
// Runs the extractor pipeline (bake/pipeline.h, Decoret et al. 1999) over a city's viewing cells (oriented street
// edges) into an impostor store directory (farfield/store/impostor_store.h): PVS, near/far split, the single mesh of
// the far objects and the multi-mesh impostors, captures on the GL thread, meshes on the other core(s), with a
// progress bar. `--technique depth-mesh|grid-mesh` (also the default without --pipeline) is Sillion et al. 1997's
// cell impostor, which is the pipeline's single stage: `--pipeline near-far,single --layer-mesh depth-mesh|grid
// --station-spacing 0` (one capture at each cell's start); it says so. `--shard K/N` bakes part K of N of the cells
// into a shard database (bake/shard.h; `farfield merge` joins them); `--resume` continues a killed bake.
#include <cstdio>
#include <functional>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "cli_util.h"
#include "bake_report.h"
#include "command.h"
#include "farfield/bake/bake.h"
#include "farfield/bake/pipeline.h"
#include "farfield/extract/pipeline_options.h"
#include "farfield/core/error.h"
#include "farfield/gen/camera_path.h"
#include "farfield/gen/city.h"
#include "farfield/gpu/context.h"
#include "farfield/scene/import.h"
#include "farfield/urban/cells.h"

namespace farfield::app {
namespace {

struct BakeArgs {
  std::string scene;
  std::string streets;
  std::string technique;  // Sillion's cell impostor: an alias of --pipeline near-far,single (the default)
  std::string local = "edge";
  std::string lookup = "street";
  int resolution = 512;
  float fov_deg = 60.0f;
  float eye_height = 1.7f;
  std::string path;
  size_t limit = 0;
  std::string cells;
  int workers = 0;
  bool list = false;
  std::string out_dir;
  // Extractor pipeline (Decoret 1999): --pipeline pvs,near-far,single,mmi and its options.
  std::string pipeline;
  std::string online;
  double error_px = 10.0;
  std::string frame_size = "640x360";
  float frame_fov = 60.0f;
  float station_spacing = 5.0f;
  std::string layer_mesh = "grid";
  int grid_cells = 30;
  std::string views = "street";
  float pvs_spacing = 2.0f;
  int pvs_face = 128;
  bool pvs_no_occlusion = false;
  float near_radius = 0.0f;
  std::string landmarks;
  double landmark_boost = 2.0;
  std::string shard;
  bool resume = false;
};

std::vector<uint32_t> parseCells(const std::string& text, const char* what = "--cells") {
  std::vector<uint32_t> cells;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');) {
    size_t used = 0;
    unsigned long v = 0;
    try {
      v = std::stoul(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() || v >= 0xffffffffUL)
      throw Error(what, "expected comma-separated ids, got '" + item + "'");
    cells.push_back(uint32_t(v));
  }
  return cells;
}

// The extractor pipeline (bake/pipeline.h): per cell PVS, near/far split, layers and their impostors.
// The pipeline and its options from the arguments (--technique resolved into them by runBakeCommand).
extract::PipelineOptions pipelineOptions(const BakeArgs& args) {
  extract::PipelineOptions options;
  options.base.resolution = args.resolution;
  options.base.fov_deg = args.fov_deg;
  options.base.eye_height = args.eye_height;
  options.base.workers = args.workers;
  options.base.scene_label = args.scene;
  options.error_px = args.error_px;
  const IVec2 frame = parseSize("--frame-size", args.frame_size);
  options.frame_width = frame.x;
  options.frame_height = frame.y;
  options.frame_fov_deg = args.frame_fov;
  options.station_spacing = args.station_spacing;
  options.mesh = extract::parseLayerMesh(args.layer_mesh);
  options.grid_cells = args.grid_cells;
  options.views = extract::parseLayerViews(args.views);
  options.pvs.spacing = args.pvs_spacing;
  options.pvs.face_size = args.pvs_face;
  options.pvs.occlusion_culling = !args.pvs_no_occlusion;
  options.near_radius = args.near_radius;
  if (!args.landmarks.empty()) options.landmarks = parseCells(args.landmarks, "--landmarks");
  options.events.landmark_boost = args.landmark_boost;
  extract::validatePipelineOptions(options);
  return options;
}

void runPipelineBake(const BakeArgs& args, const extract::PipelineSpec& spec, const extract::PipelineOptions& options,
                     const scene::Scene& scene, const urban::CellMap& cells, const std::vector<uint32_t>& requested) {
  printPipelineSetup(spec, options);
  bake::BakeControl control;
  if (!args.shard.empty()) control.shard = bake::parseShard(args.shard);
  control.resume = args.resume;
  const bake::PipelineReport report = bake::bakePipeline(gpu::sharedHeadlessContext(), scene, cells, requested,
                                                         spec, options, args.out_dir, control);
  printPipelineReport(report, scene.objects.size(), args.list, args.resume, args.out_dir);
}

// --technique depth-mesh|grid-mesh (Sillion 1997) is the pipeline near-far,single with that mesh and one capture
// station at each cell's start; `given` tells which options the user set (they must not contradict the alias).
void resolveTechnique(BakeArgs& args, const std::function<bool(const char*)>& given) {
  if (args.pipeline.empty() && args.technique.empty()) args.technique = extract::kDepthMesh;
  if (args.technique.empty()) return;
  if (!args.pipeline.empty())
    throw Error("--technique", "is an alias of --pipeline " + std::string(extract::kTechniquePipeline) +
                                   "; give one or the other");
  const extract::LayerMesh mesh = extract::techniqueMesh(args.technique);
  for (const char* option : {"--layer-mesh", "--station-spacing", "--online"})
    if (given(option))
      throw Error(option, "--technique " + args.technique + " sets it; use --pipeline " +
                              extract::kTechniquePipeline + " with " + option + " instead");
  args.pipeline = extract::kTechniquePipeline;
  args.layer_mesh = extract::layerMeshName(mesh);
  args.station_spacing = 0.0f;
  std::printf("technique:     %s is Sillion 1997's cell impostor, the pipeline's single stage: --pipeline %s "
              "--layer-mesh %s --station-spacing 0\n",
              args.technique.c_str(), extract::kTechniquePipeline, args.layer_mesh.c_str());
}

void runBakeCommand(BakeArgs args, const std::function<bool(const char*)>& given) {
  urban::CellOptions cell_options;
  cell_options.local = urban::parseLocalModel(args.local);
  cell_options.lookup = urban::parseCellLookup(args.lookup, "--cell-lookup");
  if (args.out_dir.empty()) throw Error("-o", "an output directory is needed");

  // Cheap inputs first: pipeline options, streets and path fail before the scene is loaded.
  resolveTechnique(args, given);
  if (!args.shard.empty()) bake::parseShard(args.shard);
  const extract::PipelineSpec spec = extract::parsePipeline(args.pipeline, args.online);
  const extract::PipelineOptions options = pipelineOptions(args);
  const std::string streets_file = args.streets.empty() ? gen::streetsPathFor(args.scene) : args.streets;
  urban::StreetGraph graph = urban::StreetGraph::load(streets_file);
  gen::CameraPath path;
  if (!args.path.empty()) path = gen::loadCameraPath(args.path);
  std::vector<uint32_t> requested;
  if (!args.cells.empty()) requested = parseCells(args.cells);
  const scene::Scene scene = scene::loadScene(args.scene);
  const urban::CellMap cells(std::move(graph), scene, cell_options);

  if (!args.path.empty()) {
    const std::vector<uint32_t> visited = bake::cellsOnPath(cells, path);
    requested.insert(requested.end(), visited.begin(), visited.end());
    std::printf("path:          %s visits %zu cells\n", args.path.c_str(), visited.size());
  }
  if (requested.empty())
    for (uint32_t e = 0; e < cells.cellCount(); ++e) requested.push_back(e);
  if (args.limit > 0 && requested.size() > args.limit) requested.resize(args.limit);

  const urban::BlockAssignment& a = cells.assignment();
  const size_t in_blocks = a.object_face.size() - a.shared.size();
  std::printf("scene:         %s (%zu objects, %llu triangles)\n", args.scene.c_str(), scene.objects.size(),
              (unsigned long long)scene.triangleCount());
  std::printf("streets:       %s (%zu streets, %zu blocks, %zu cells)\n", streets_file.c_str(),
              cells.graph().streetCount(), cells.graph().blockCount(), cells.cellCount());
  std::printf("segmentation:  local model = %s, cell lookup = %s; %zu objects in blocks, %zu shared (%zu without footprint, %zu in no "
              "block, %zu larger than their block)\n",
              urban::localModelName(cell_options.local), urban::cellLookupName(cell_options.lookup), in_blocks, a.shared.size(), a.without_footprint,
              a.outside_blocks, a.too_large);

  runPipelineBake(args, spec, options, scene, cells, requested);
}

const RegisterCommand reg("bake", [](CLI::App& app) {
  auto args = std::make_shared<BakeArgs>();
  auto* cmd = app.add_subcommand("bake", "Run the extractor pipeline (Decoret 1999: pvs, near-far, single, mmi) over "
                                         "the street cells (oriented edges) into an impostor store directory; "
                                         "--technique depth-mesh|grid-mesh is Sillion 1997's cell impostor, the "
                                         "pipeline near-far,single.");
  cmd->add_option("scene", args->scene, "Scene file (the city .glb)")->required();
  cmd->add_option("--streets", args->streets, "Street graph JSON (default: the .streets.json next to the scene)");
  cmd->add_option("--technique", args->technique, "Sillion 1997's cell impostor: depth-mesh or grid-mesh, an alias of "
                                                  "--pipeline near-far,single --layer-mesh depth-mesh|grid "
                                                  "--station-spacing 0 (the default without --pipeline)");
  cmd->add_option("--local", args->local, "Local model: edge (blocks touching the street) or junction (also the "
                                          "blocks around both end junctions)")
      ->capture_default_str();
  cmd->add_option("--resolution", args->resolution, "Impostor image size (square), pixels")->capture_default_str();
  cmd->add_option("--fov", args->fov_deg, "Field of view of the creation camera, degrees")->capture_default_str();
  cmd->add_option("--eye-height", args->eye_height, "Creation camera height above the ground, metres")
      ->capture_default_str();
  cmd->add_option("--path", args->path, "Bake only the cells this camera path visits");
  cmd->add_option("--cell-lookup", args->lookup, "How a viewer's cell is found: street (best-aligned street the "
                                                 "viewer stands on) or nearest (nearest agreeing edge)")
      ->capture_default_str();
  cmd->add_option("--cells", args->cells, "Bake these half-edge ids (comma-separated)");
  cmd->add_option("--limit", args->limit, "Bake at most N cells (0 = no limit)");
  cmd->add_option("--workers", args->workers, "Worker threads for the constructions (0 = cores - 1, at least 1)")
      ->capture_default_str();
  cmd->add_flag("--list", args->list, "Print one line per baked cell");
  cmd->add_option("--pipeline", args->pipeline, "Extractor pipeline (Decoret 1999): stages from pvs, near-far, single, "
                                                "mmi in that order, e.g. pvs,near-far,single,mmi");
  cmd->add_option("--online", args->online, "Pipeline stages left to the runtime (the pipeline's tail: mmi, or "
                                            "single,mmi, or near-far,single,mmi); the rest is baked");
  cmd->add_option("--error-px", args->error_px, "Error bound, pixels: the layering threshold and the bound the "
                                                "validity regions are computed for")
      ->capture_default_str();
  cmd->add_option("--frame-size", args->frame_size, "Error bound: size WxH of the walkthrough's frames")
      ->capture_default_str();
  cmd->add_option("--frame-fov", args->frame_fov, "Error bound: vertical field of view of the walkthrough, degrees")
      ->capture_default_str();
  cmd->add_option("--station-spacing", args->station_spacing, "Capture stations along each cell, metres apart "
                                                              "(0: the cell's start only); unneeded ones are dropped")
      ->capture_default_str();
  cmd->add_option("--layer-mesh", args->layer_mesh, "Mesh of each layer and of the single mesh: grid (regular grid) "
                                                  "or depth-mesh")
      ->capture_default_str();
  cmd->add_option("--grid-cells", args->grid_cells, "Regular grid layer mesh: cells per side")->capture_default_str();
  cmd->add_option("--views", args->views, "Views per layer: street (along the cell) or six (360 degrees)")
      ->capture_default_str();
  cmd->add_option("--pvs-spacing", args->pvs_spacing, "PVS: metres between sample points along the cell")
      ->capture_default_str();
  cmd->add_option("--pvs-face", args->pvs_face, "PVS: cube face size, pixels")->capture_default_str();
  cmd->add_flag("--pvs-no-occlusion", args->pvs_no_occlusion,
                "PVS: draw every cluster in each face's frustum, without occlusion culling (the same PVS, slower: "
                "a reference for measurements)");
  cmd->add_option("--landmarks", args->landmarks, "MMI layering: object ids of landmarks (comma-separated), whose "
                                                  "visibility-event weights are boosted");
  cmd->add_option("--landmark-boost", args->landmark_boost, "MMI layering: weight factor of landmark relations (>= 1)")
      ->capture_default_str();
  cmd->add_option("--near-radius", args->near_radius, "Near/far by distance to the street (metres) instead of the "
                                                      "local model (0)")
      ->capture_default_str();
  cmd->add_option("--shard", args->shard, "Bake part K of N (0 <= K < N) of the cells, balanced by estimated work, "
                                          "into a shard database; join the N shards with farfield merge");
  cmd->add_flag("--resume", args->resume, "Continue the bake killed in the output directory (its journal), keeping "
                                          "the cells it finished; a finished bake is left as it is");
  cmd->add_option("-o,--output", args->out_dir, "Impostor store directory")->required();
  cmd->callback([args, cmd] {
    runBakeCommand(*args, [cmd](const char* option) { return cmd->count(option) > 0; });
  });
});

}  // namespace
}  // namespace farfield::app
