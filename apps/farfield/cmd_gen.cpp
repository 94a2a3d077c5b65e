// farfield gen city --blocks N --seed S [--detail D] [--hill | --terrain DEM|fractal:... [--terrain-scale S]]
//                   [--objects blocks|buildings] [--trees] -o city.glb
// farfield gen forest [--size M] [--trees N] [--leaves L] [--seed S] -o forest.glb
// Generates a procedural city (farfield/gen/city.h), writes it as binary glTF and its street graph as
// city.streets.json next to it, and prints what was made and what it cost.
#include <sys/resource.h>

#include <cstdio>
#include <memory>
#include <string>

#include "city_terrain.h"
#include "cli_util.h"
#include "command.h"
#include "farfield/core/error.h"
#include "farfield/core/timer.h"
#include "farfield/gen/city.h"
#include "farfield/gen/vegetation.h"
#include "farfield/scene/export_gltf.h"

namespace farfield::app {
namespace {

struct CityArgs {
  int blocks = 100;
  uint64_t seed = 1;
  int detail = 1;
  bool hill = false;
  std::string terrain;
  float terrain_scale = 1.0f;
  std::string objects = "blocks";
  bool trees = false;
  float park_share = 0.1f;
  int tree_leaves = 300;
  std::string output;
};

struct ForestArgs {
  gen::ForestOptions options;
  std::string output;
};

double peakMemoryMiB() {
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0.0;
  return double(usage.ru_maxrss) / 1024.0;  // Linux reports kilobytes
}

void runCity(const CityArgs& args) {
  gen::CityOptions options;
  options.blocks = args.blocks;
  options.seed = args.seed;
  options.detail = args.detail;
  options.hill = args.hill;
  options.objects = args.objects == "buildings" ? gen::ObjectGrouping::Buildings : gen::ObjectGrouping::Blocks;
  options.trees = args.trees;
  options.park_share = args.park_share;
  options.tree_leaves = args.tree_leaves;
  if (!args.terrain.empty())
    std::printf("terrain:    %s\n", setCityTerrain(options, args.terrain, args.terrain_scale).c_str());

  Stopwatch clock;
  const gen::City city = gen::generateCity(options);
  const double generate_s = clock.seconds();
  const double generate_peak_mib = peakMemoryMiB();
  const scene::SceneStats s = city.scene.stats();

  clock.restart();
  ensureParentDirectory(args.output);
  scene::exportGlb(city.scene, args.output);
  const std::string streets = gen::streetsPathFor(args.output);
  city.streets.save(streets);
  const double write_s = clock.seconds();

  std::printf("city:       %d blocks requested, seed %llu, detail %d%s, one object per %s\n", args.blocks,
              (unsigned long long)args.seed, args.detail, args.hill ? ", hill" : "",
              options.objects == gen::ObjectGrouping::Blocks ? "block" : "building");
  std::printf("blocks:     %zu (street graph faces; %zu without buildings)\n", city.streets.blockCount(),
              city.skipped_blocks);
  std::printf("streets:    %zu segments, %zu junctions\n", city.streets.streetCount(), city.streets.junctionCount());
  std::printf("buildings:  %zu (%zu landmarks)%s\n", city.buildings, city.landmarks,
              city.skipped_lots ? (", " + std::to_string(city.skipped_lots) + " degenerate lots dropped").c_str() : "");
  if (args.trees) std::printf("trees:      %zu (%zu park blocks)\n", city.trees, city.parks);
  std::printf("objects:    %zu\n", s.objects);
  std::printf("triangles:  %llu\n", (unsigned long long)s.triangles);
  std::printf("vertices:   %llu\n", (unsigned long long)s.vertices);
  std::printf("geometry:   %.1f MiB\n", double(s.geometry_bytes) / (1024.0 * 1024.0));
  std::printf("textures:   %zu (%.1f MiB)\n", s.textures, double(s.texture_bytes) / (1024.0 * 1024.0));
  if (!s.bounds.empty())
    std::printf("bounds:     [%.1f, %.1f, %.1f] .. [%.1f, %.1f, %.1f] m\n", s.bounds.lo.x, s.bounds.lo.y, s.bounds.lo.z,
                s.bounds.hi.x, s.bounds.hi.y, s.bounds.hi.z);
  std::printf("time:       %.2f s generation, %.2f s writing\n", generate_s, write_s);
  std::printf("memory:     %.0f MiB peak resident (%.0f MiB after generation)\n", peakMemoryMiB(), generate_peak_mib);
  std::printf("wrote:      %s\n", args.output.c_str());
  if (scene::isGltfPath(args.output))
    std::printf("            %s\n", scene::gltfBufferPath(args.output).c_str());
  std::printf("            %s\n", streets.c_str());
}

void runForest(const ForestArgs& args) {
  Stopwatch clock;
  const scene::Scene forest = gen::generateForest(args.options);
  const scene::SceneStats s = forest.stats();
  ensureParentDirectory(args.output);
  scene::exportGlb(forest, args.output);
  std::printf("forest:     %.0f m square, %zu trees, seed %llu\n", args.options.size, s.objects - 1,
              (unsigned long long)args.options.seed);
  std::printf("triangles:  %llu\n", (unsigned long long)s.triangles);
  std::printf("time:       %.2f s\n", clock.seconds());
  std::printf("wrote:      %s\n", args.output.c_str());
}

const RegisterCommand reg("gen", [](CLI::App& app) {
  auto* cmd = app.add_subcommand("gen", "Generate procedural content.");
  cmd->require_subcommand(1);

  auto city = std::make_shared<CityArgs>();
  auto* c = cmd->add_subcommand("city", "A procedural city: street graph, blocks of buildings, landmarks.");
  c->add_option("--blocks", city->blocks, "Number of blocks (street graph faces), 10..200000")
      ->check(CLI::Range(10, 200000));
  c->add_option("--seed", city->seed, "Random seed (the same seed gives the same city)");
  c->add_option("--detail", city->detail, "Facade detail 0..4 (0 plain, 1 ledges, 2 windows, 3 balconies, 4 dense)")
      ->check(CLI::Range(0, 4));
  c->add_flag("--hill", city->hill, "A hill in the middle of the city");
  c->add_option("--terrain", city->terrain,
                "The city on a terrain: a DEM file or fractal:SIZE[:SEED][:relief=M][:roughness=R][:cell=M], "
                "its centre under the city's")
      ->excludes("--hill");
  c->add_option("--terrain-scale", city->terrain_scale, "With --terrain: vertical scale of its heights (default 1)");
  c->add_option("--objects", city->objects, "One object per block (blocks) or per building (buildings)")
      ->check(CLI::IsMember({"blocks", "buildings"}));
  c->add_option("-o,--output", city->output,
                "Output scene (.glb, or .gltf + .bin for scenes over the 4 GiB of a .glb); the street graph goes next to "
                "it")
      ->required();
  c->add_flag("--trees", city->trees, "Street trees along the blocks and parks (gen/vegetation.h)");
  c->add_option("--park-share", city->park_share, "With --trees: share of blocks turned into parks, 0..1")
      ->check(CLI::Range(0.0f, 1.0f));
  c->add_option("--tree-leaves", city->tree_leaves, "With --trees: leaf triangles per tree (about)")
      ->check(CLI::Range(1, 100000));
  c->callback([city] { runCity(*city); });

  auto forest = std::make_shared<ForestArgs>();
  auto* f = cmd->add_subcommand("forest", "A forest of procedural trees on rolling ground (not a city).");
  f->add_option("--size", forest->options.size, "Square side, metres")->check(CLI::Range(20.0f, 20000.0f));
  f->add_option("--trees", forest->options.trees, "Number of trees")->check(CLI::Range(1, 200000));
  f->add_option("--leaves", forest->options.tree.leaves, "Leaf triangles per tree (about)")
      ->check(CLI::Range(1, 100000));
  f->add_option("--seed", forest->options.seed, "Random seed");
  f->add_option("-o,--output", forest->output, "Output scene (.glb, or .gltf + .bin)")->required();
  f->callback([forest] { runForest(*forest); });
});

}  // namespace
}  // namespace farfield::app
