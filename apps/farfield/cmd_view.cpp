// farfield view SCENE [--impostors DB] [--mode M] [--path P | --replay P] [--screenshot-at N,M -o DIR] [--exit]
//               [--record OUT.json] [--size WxH] [--tmax MS] [--error-px PX] [--streets FILE] [--walk] [--tint]
//               [--terrain DEM|fractal:... [--terrain-scale S]] [--crowd N [--crowd-models a.glb,b.glb] ...]
// The interactive viewer (farfield/view/viewer.h): a window with panels over the runtime; keys in docs/VIEWER.md.
// The allocator is set up for timing first (farfield/core/allocator.h).
#include <memory>
#include <sstream>

#include "cli_util.h"
#include "command.h"
#include "farfield/core/allocator.h"
#include "farfield/core/error.h"
#include "farfield/scene/import.h"
#include "farfield/view/viewer.h"

namespace farfield::app {
namespace {

struct ViewArgs {
  view::ViewerOptions options;
  std::string scene;
  std::string size = "1280x720";
  std::string screenshot_at;
  bool walk = false;
  std::string crowd_models;  // empty: the built-in figures
};

std::vector<size_t> parseFrameList(const std::string& option, const std::string& text) {
  std::vector<size_t> frames;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');) {
    size_t used = 0;
    unsigned long long n = 0;
    try {
      n = std::stoull(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() || item[0] == '-')
      throw Error(option, "expected frame numbers like 0,10,20, got '" + text + "'");
    frames.push_back(size_t(n));
  }
  if (frames.empty()) throw Error(option, "no frame numbers given");
  return frames;
}

void runViewCommand(ViewArgs& args) {
  configureTimingAllocator();
  view::ViewerOptions& o = args.options;
  const IVec2 size = parseSize("--size", args.size);
  o.width = size.x;
  o.height = size.y;
  if (!args.screenshot_at.empty()) o.screenshot_at = parseFrameList("--screenshot-at", args.screenshot_at);
  if (args.walk) o.navigation = view::Navigation::Walk;
  o.scene_file = args.scene;
  o.crowd.models = splitList(args.crowd_models);
  view::checkViewerOptions(o);  // cheap checks before the scene is loaded
  const scene::Scene scene = scene::loadScene(args.scene);
  view::runViewer(scene, o);
}

const RegisterCommand reg("view", [](CLI::App& app) {
  auto args = std::make_shared<ViewArgs>();
  view::ViewerOptions& o = args->options;
  auto* cmd = app.add_subcommand("view", "Interactive viewer: fly or walk through a scene in every mode its impostor "
                                         "database offers, with the two promises measured (docs/VIEWER.md).");
  cmd->add_option("scene", args->scene, "Scene file (glTF, OBJ, ...) or builtin:NAME")->required();
  cmd->add_option("--impostors", o.impostors, "Impostor database: farfield bake --pipeline or farfield place output");
  cmd->add_option("--mode", o.mode, "Starting mode (default: the database's best, else full; over a placement, "
                                    "governed: placed under the frame governor, keeping --tmax)");
  cmd->add_option("--path", o.path, "Camera path to play in real time, looping (P pauses)");
  cmd->add_option("--replay", o.replay, "Camera path to show one frame per displayed frame (scripted runs)");
  cmd->add_option("--screenshot-at", args->screenshot_at,
                  "Frames to write as DIR/frame_N.png and DIR/window_N.png (replay frame numbers)");
  cmd->add_option("-o,--output", o.out_dir, "Directory for screenshots")->capture_default_str();
  cmd->add_flag("--exit", o.exit_at_end, "Close after the replay (or the last screenshot); errors close at once");
  cmd->add_option("--record", o.record, "Write the cameras shown to this camera path file at exit");
  cmd->add_option("--size", args->size, "Window and frame size WxH")->capture_default_str();
  cmd->add_option("--tmax", o.t_max_ms, "Frame budget in ms the panel counts frames against, and the governed "
                                        "mode keeps (0 = none)");
  cmd->add_option("--error-px", o.error_px, "Error bound in pixels for the walkthrough (default: the database's)");
  cmd->add_option("--streets", o.streets, "Street graph for the map (default: the database's, or next to the scene)");
  cmd->add_flag("--walk", args->walk, "Start walking (eye 1.7 m above the ground) instead of flying");
  cmd->add_flag("--tint", o.tint, "Tint impostors by kind");
  cmd->add_flag("--check-every-frame", o.check_every_frame, "Compare every frame with full geometry (slow)");
  cmd->add_option("--terrain", o.terrain,
                  "Terrain under the city in full and culled (drawn by --terrain-technique): the DEM or fractal:... "
                  "the city was made on (gen city --terrain)");
  cmd->add_option("--terrain-scale", o.terrain_scale, "Vertical scale the city was made with (gen city --terrain-scale)")
      ->capture_default_str();
  cmd->add_option("--terrain-technique", o.terrain_technique,
                  "How the terrain is drawn: lod-sprite-gpu (LOD-sprite over CDLOD keyframes on the GPU), high-gpu "
                  "(CDLOD at 1 px), lod-sprite or high (the quadtree LOD remade on the CPU every frame)")
      ->capture_default_str()
      ->check(CLI::IsMember({"lod-sprite-gpu", "high-gpu", "lod-sprite", "high"}));
  cmd->add_flag_callback(
      "--terrain-gpu", [args] { args->options.terrain_technique = "high-gpu"; },
      "The same as --terrain-technique high-gpu");
  cmd->add_option("--crowd", o.crowd.agents,
                  "Agents walking the sidewalks of the street graph, drawn over every mode as crowd-mixed (0: none)")
      ->capture_default_str();
  cmd->add_option("--crowd-models", args->crowd_models,
                  "Skinned glTF models of the crowd, comma-separated (heights 1.75, 0.8 m, as the shared CesiumMan "
                  "and Fox); default: the built-in figures, a walker and a four-legged one, no file read");
  cmd->add_option("--crowd-seed", o.crowd.seed, "Crowd seed")->capture_default_str();
  cmd->add_option("--crowd-error-px", o.crowd.error_px, "The crowd impostors' error bound (pixels)")
      ->capture_default_str();
  cmd->add_option("--crowd-lod-px", o.crowd.lod_px,
                  "Skinned agents at levels of detail within this many pixels (0: the mesh; seconds to build)")
      ->capture_default_str();
  cmd->add_option("--crowd-triangles", o.crowd.max_triangles,
                  "Skinned triangles a frame for the nearest agents, the others as impostors (0: no budget)")
      ->capture_default_str();
  cmd->add_option("--crowd-ms", o.crowd.geometry_ms,
                  "Skinned drawing a frame in ms, at the measured time per triangle (0: none; with --crowd-triangles "
                  "the smaller holds)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--crowd-gpu", o.crowd.gpu,
                "The crowd simulated, culled (behind the city too), classified, drawn and shadowed on the GPU "
                "(--crowd-triangles, --crowd-ms and --crowd-lod-px hold there too)");
  cmd->callback([args] { runViewCommand(*args); });
});

}  // namespace
}  // namespace farfield::app
