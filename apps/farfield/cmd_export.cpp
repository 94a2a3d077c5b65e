// farfield export SCENE [--impostors DB] -o out.glb
// farfield export SCENE --tiles DIR [--error-px N --size WxH --fov F] [--leaf-objects K] [--texels R]
#include <cstdio>
#include <memory>

#include "cli_util.h"
#include "command.h"
#include "farfield/core/error.h"
#include "farfield/geodata/projection.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/renderer.h"
#include "farfield/scene/import.h"
#include "farfield/store/export_georef.h"
#include "farfield/store/export_impostors.h"
#include "farfield/store/export_tiles.h"

namespace farfield::app {
namespace {

struct ExportArgs {
  std::string scene, impostors, output, tiles;
  double error_px = 2.0;
  std::string size = "1920x1080";
  double fov_deg = 60.0;
  size_t leaf_objects = 8;
  int texels = 0;
};

void exportGlbFile(const scene::Scene& scene, const ExportArgs& args) {
  ensureParentDirectory(args.output);
  size_t bytes = 0;
  const store::ImpostorExportStats s = store::exportSceneAndImpostors(scene, args.impostors, args.output, &bytes);
  std::printf("wrote %s: %zu objects, %.1f MB\n", args.output.c_str(), scene.objects.size(), double(bytes) / 1e6);
  if (!args.impostors.empty())
    std::printf("impostors (%s %s): %zu in %zu view regions, %zu meshes, %zu triangles, %zu layers, %zu empty views\n",
                s.database.c_str(), args.impostors.c_str(), s.impostors, s.regions, s.meshes, s.triangles, s.layers,
                s.empty);
}

void exportTileset(const scene::Scene& scene, const ExportArgs& args) {
  store::TilesOptions options;
  const IVec2 size = parseSize("--size", args.size);
  options.bound = {args.error_px, size.x, size.y, degToRad(args.fov_deg)};
  options.leaf_objects = args.leaf_objects;
  options.texels = args.texels;
  options.scene_name = args.scene;
  options.georeference = store::readGeoOrigin(geodata::geoReferencePathFor(args.scene));
  gpu::sharedHeadlessContext();
  const gpu::GpuScene gpu_scene(scene);
  gpu::Renderer renderer;
  const store::CaptureFn capture = [&](const Camera& camera, std::span<const uint32_t> objects) {
    return impostor::captureView(renderer, gpu_scene, objects, camera);
  };
  const store::TilesetStats s = store::exportTiles(scene, capture, args.tiles, options);
  std::printf("wrote %s/tileset.json: %zu tiles (%zu leaves of full geometry, %zu textured heightfield impostors), %d levels, "
              "%.1f MB, %d texels a side\n",
              args.tiles.c_str(), s.tiles.size(), s.leaves, s.inner, s.depth + 1, double(s.bytes) / 1e6, s.texels);
  std::printf("geometric error: root %.2f m, tileset %.2f m; frame: %s\n", s.root_error, s.tileset_error,
              options.georeference ? "east-north-up at the georeference" : "local (no georeference)");
  std::printf("viewer: maximumScreenSpaceError %.2f keeps %.1f px at %s, %.0f deg\n", s.max_sse, args.error_px,
              args.size.c_str(), args.fov_deg);
}

void runExport(const ExportArgs& args) {
  if (args.output.empty() == args.tiles.empty()) throw Error("export", "give either -o FILE.glb or --tiles DIR");
  if (!args.tiles.empty() && !args.impostors.empty())
    throw Error("--impostors", "goes with -o FILE.glb; a tileset makes its own impostors");
  const scene::Scene scene = scene::loadScene(args.scene);
  if (!args.tiles.empty())
    exportTileset(scene, args);
  else
    exportGlbFile(scene, args);
}

const RegisterCommand reg("export", [](CLI::App& app) {
  auto args = std::make_shared<ExportArgs>();
  auto* cmd = app.add_subcommand("export", "Write the scene and its baked impostors as glTF 2.0 (.glb), or the scene "
                                           "as a 3D Tiles 1.1 tileset whose distant levels are impostors.");
  cmd->add_option("scene", args->scene, "Scene file or builtin:NAME")->required();
  cmd->add_option("--impostors", args->impostors, "Impostor database (farfield bake or farfield place) to add");
  cmd->add_option("-o,--output", args->output, "The .glb to write");
  cmd->add_option("--tiles", args->tiles, "Write a 3D Tiles tileset into this directory instead");
  cmd->add_option("--error-px", args->error_px, "Tiles: error bound, pixels")->capture_default_str();
  cmd->add_option("--size", args->size, "Tiles: frame size WxH of the bound")->capture_default_str();
  cmd->add_option("--fov", args->fov_deg, "Tiles: vertical field of view of the bound, degrees")->capture_default_str();
  cmd->add_option("--leaf-objects", args->leaf_objects, "Tiles: at most this many objects per leaf tile")
      ->capture_default_str();
  cmd->add_option("--texels", args->texels, "Tiles: capture resolution of inner tiles (0: the frame height)")
      ->capture_default_str();
  cmd->callback([args] { runExport(*args); });
});

}  // namespace
}  // namespace farfield::app
