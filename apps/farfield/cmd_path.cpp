// farfield path street STREETS.json [--frames N] [--seed S] [--car] [--fps F] [--fov DEG] [--turn-radius M]
//                     [--hill | --terrain SPEC [--terrain-scale S]] -o FILE
// farfield path flyover SCENE [--frames N] [--fps F] [--altitude M] [--fov DEG] -o FILE
// farfield path views SCENE [--frames N] [--seed S] [--view-min X,Y,Z --view-max X,Y,Z] [--fov DEG] -o FILE
// farfield path orbit SCENE [--frames N] [--fps F] [--radius-scale K] [--elevation DEG] [--fov DEG] -o FILE
// farfield path cut PATH.json --from A [--to B] -o FILE
// Writes a camera path (JSON, see farfield/gen/camera_path.h) for the walkthrough benchmark.
#include <cstddef>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "city_terrain.h"
#include "cli_util.h"
#include "command.h"
#include "farfield/bake/place.h"
#include "farfield/core/error.h"
#include "farfield/eval/calibration.h"
#include "farfield/gen/camera_path.h"
#include "farfield/gen/city.h"
#include "farfield/scene/import.h"
#include "farfield/urban/street_graph.h"

namespace farfield::app {
namespace {

struct PathArgs {
  std::string input;
  std::string output;
  int frames = 600;
  uint64_t seed = 1;
  bool car = false;
  bool hill = false;
  std::string terrain;
  float terrain_scale = 1.0f;
  float fps = 30.0f;
  float fov_deg = 0.0f;  // 0: the default of each kind
  float turn_radius = 6.0f;
  float altitude = 150.0f;
  float radius_scale = 1.2f;
  float elevation_deg = 25.0f;
  std::string view_min, view_max;
  size_t from = 0, to = 0;  // cut: frames [from, to] (to 0: the last)
};

void writeAndReport(const gen::CameraPath& path, const std::string& output, const std::string& what) {
  ensureParentDirectory(output);
  gen::saveCameraPath(path, output);
  double length = 0.0;
  for (size_t i = 1; i < path.frames.size(); ++i) length += glm::length(path.frames[i].eye - path.frames[i - 1].eye);
  const double duration = double(path.frames.size()) / path.fps;
  std::printf("wrote %s: %s, %zu frames, %.1f m, %.1f s at %.0f fps\n", output.c_str(), what.c_str(),
              path.frames.size(), length, duration, double(path.fps));
}

void runStreet(const PathArgs& args) {
  const urban::StreetGraph graph = urban::StreetGraph::load(args.input);
  gen::StreetWalkOptions options;
  options.frames = args.frames;
  options.seed = args.seed;
  options.walker = args.car ? gen::Walker::Car : gen::Walker::Pedestrian;
  options.fps = args.fps;
  if (args.fov_deg > 0.0f) options.fov_deg = args.fov_deg;
  options.turn_radius = args.turn_radius;
  if (args.hill || !args.terrain.empty()) {
    // The streets file keeps only the plan; the ground of a `gen city --hill` or `--terrain` city is a function of
    // its bounds (and of the same terrain spec and scale).
    gen::CityOptions city;
    city.hill = args.hill;
    if (!args.terrain.empty()) setCityTerrain(city, args.terrain, args.terrain_scale);
    const Box2 bounds = graph.bounds();
    options.ground_height = [city, bounds](float x, float y) { return gen::cityGroundHeight(city, bounds, {x, y}); };
  }
  const gen::CameraPath path = gen::streetWalk(graph, options);
  writeAndReport(path, args.output,
                 std::string("street walk (") + (args.car ? "car, 10 m/s" : "pedestrian, 1.4 m/s") + ", " +
                     std::to_string(graph.streetCount()) + " streets, " + std::to_string(graph.blockCount()) +
                     " blocks)");
}

Box3 sceneBounds(const std::string& spec) {
  const scene::Scene scene = scene::loadScene(spec);
  const Box3 bounds = scene.bounds();
  if (bounds.empty()) throw Error(spec, "the scene is empty (no bounds to fly over)");
  return bounds;
}

void runFlyover(const PathArgs& args) {
  gen::FlyoverOptions options;
  options.frames = args.frames;
  options.fps = args.fps;
  options.altitude = args.altitude;
  if (args.fov_deg > 0.0f) options.fov_deg = args.fov_deg;
  writeAndReport(gen::flyover(sceneBounds(args.input), options), args.output, "flyover");
}

void runOrbit(const PathArgs& args) {
  gen::OrbitOptions options;
  options.frames = args.frames;
  options.fps = args.fps;
  options.radius_scale = args.radius_scale;
  options.elevation_deg = args.elevation_deg;
  if (args.fov_deg > 0.0f) options.fov_deg = args.fov_deg;
  writeAndReport(gen::orbit(sceneBounds(args.input), options), args.output, "orbit");
}

void addCommon(CLI::App* cmd, PathArgs& args) {
  cmd->add_option("--frames", args.frames, "Number of frames")->check(CLI::Range(1, 10000000));
  cmd->add_option("--fps", args.fps, "Frames per second")->check(CLI::PositiveNumber);
  cmd->add_option("--fov", args.fov_deg, "Vertical field of view, degrees")->check(CLI::Range(1.0, 179.0));
  cmd->add_option("-o,--output", args.output, "Output camera path (.json)")->required();
}

// Independent random views of a view space (eye uniform in the box, any heading, pitch within 10 degrees): the
// "random path" of placement's experiments, which visits problem views a street walk may never reach.
void runViews(const PathArgs& args) {
  const scene::Scene scene = scene::loadScene(args.input);
  Box3 space = parseViewSpace(args.view_min, args.view_max);
  if (space.empty()) space = bake::defaultPlaceViewSpace(scene);
  const float fov = args.fov_deg > 0.0f ? args.fov_deg : 45.0f;
  gen::CameraPath path;
  path.kind = "random views";
  path.fps = args.fps;
  for (const Camera& c : eval::randomViews(space, size_t(args.frames), uint32_t(args.seed), 64, 64, fov, 0.5f, 1.0f))
    path.frames.push_back({c.eye, c.at, Vec3(0.0f, 0.0f, 1.0f), c.fov_y});
  writeAndReport(path, args.output, "random views");
}

// Frames [from, to] of a path (to 0: through the last), e.g. the stretch of a run that shows something.
void runCut(const PathArgs& args) {
  gen::CameraPath path = gen::loadCameraPath(args.input);
  const size_t last = args.to == 0 ? path.frames.size() - 1 : args.to;
  if (path.frames.empty() || args.from > last || last >= path.frames.size())
    throw Error(args.input, "cannot cut frames " + std::to_string(args.from) + "-" + std::to_string(last) +
                                " from a path of " + std::to_string(path.frames.size()) + " frames");
  path.frames = std::vector<gen::PathFrame>(path.frames.begin() + std::ptrdiff_t(args.from),
                                            path.frames.begin() + std::ptrdiff_t(last) + 1);
  writeAndReport(path, args.output, path.kind + ", frames " + std::to_string(args.from) + "-" + std::to_string(last));
}

const RegisterCommand reg("path", [](CLI::App& app) {
  auto* cmd = app.add_subcommand("path", "Write a camera path: a street walk, random views, a flyover or an orbit, or a cut of one.");
  cmd->require_subcommand(1);

  auto street = std::make_shared<PathArgs>();
  auto* s = cmd->add_subcommand("street", "A walk along the streets of a street graph (.streets.json).");
  s->add_option("streets", street->input, "Street graph file (city.streets.json)")->required();
  addCommon(s, *street);
  s->add_option("--seed", street->seed, "Random seed for the walk");
  s->add_flag("--hill", street->hill, "The city was made with `gen city --hill`: follow its ground");
  s->add_option("--terrain", street->terrain, "The city was made with `gen city --terrain SPEC`: follow its ground")
      ->excludes("--hill");
  s->add_option("--terrain-scale", street->terrain_scale, "With --terrain: the city's --terrain-scale");
  s->add_flag("--car", street->car, "Drive (1.2 m eye height, 10 m/s) instead of walking (1.7 m, 1.4 m/s)");
  s->add_option("--turn-radius", street->turn_radius, "Turn radius at junctions, metres")
      ->check(CLI::NonNegativeNumber);
  s->callback([street] { runStreet(*street); });

  auto fly = std::make_shared<PathArgs>();
  auto* f = cmd->add_subcommand("flyover", "A straight flight across the scene's bounds, looking ahead and down.");
  f->add_option("scene", fly->input, "Scene file or builtin:NAME")->required();
  addCommon(f, *fly);
  f->add_option("--altitude", fly->altitude, "Height above the lowest point of the scene, metres");
  f->callback([fly] { runFlyover(*fly); });

  auto views = std::make_shared<PathArgs>();
  auto* v = cmd->add_subcommand("views", "Independent random views of a view space (eye in a box, any heading, "
                                         "pitch within 10 degrees).");
  v->add_option("scene", views->input, "Scene file or builtin:NAME")->required();
  addCommon(v, *views);
  v->add_option("--seed", views->seed, "Random seed");
  v->add_option("--view-min", views->view_min, "View space corner X,Y,Z (default: the scene's bounds at 1.2-1.7 m)");
  v->add_option("--view-max", views->view_max, "View space corner X,Y,Z");
  v->callback([views] { runViews(*views); });

  auto orb = std::make_shared<PathArgs>();
  auto* o = cmd->add_subcommand("orbit", "A circle around the scene's bounds, looking at their centre.");
  o->add_option("scene", orb->input, "Scene file or builtin:NAME")->required();
  addCommon(o, *orb);
  o->add_option("--radius-scale", orb->radius_scale, "Radius as a multiple of half the bounds' diagonal")
      ->check(CLI::PositiveNumber);
  o->add_option("--elevation", orb->elevation_deg, "Elevation angle, degrees")->check(CLI::Range(-89.0, 89.0));
  o->callback([orb] { runOrbit(*orb); });

  auto cut = std::make_shared<PathArgs>();
  auto* c = cmd->add_subcommand("cut", "Frames FROM to TO of a camera path (e.g. the stretch of a run to look at).");
  c->add_option("path", cut->input, "Camera path (.json)")->required();
  c->add_option("--from", cut->from, "First frame kept (0-based)")->required();
  c->add_option("--to", cut->to, "Last frame kept (default: the path's last)");
  c->add_option("-o,--output", cut->output, "Output camera path (.json)")->required();
  c->callback([cut] { runCut(*cut); });
});

}  // namespace
}  // namespace farfield::app
