// farfield info SCENE: objects, triangles, bounds, textures.
#include <cstdio>
#include <memory>
#include <set>

#include "command.h"
#include "farfield/scene/import.h"

namespace farfield::app {
namespace {

void runInfo(const std::string& spec, bool list_objects) {
  scene::ImportStats import_stats;
  const scene::Scene scene = scene::loadScene(spec, {}, &import_stats);
  const scene::SceneStats s = scene.stats();
  std::printf("scene:      %s\n", spec.c_str());
  std::printf("objects:    %zu\n", s.objects);
  std::printf("meshes:     %zu\n", s.meshes);
  std::printf("materials:  %zu\n", s.materials);
  std::printf("triangles:  %llu\n", (unsigned long long)s.triangles);
  std::printf("vertices:   %llu\n", (unsigned long long)s.vertices);
  std::printf("geometry:   %.2f MiB\n", double(s.geometry_bytes) / (1024.0 * 1024.0));
  if (!s.bounds.empty())
    std::printf("bounds:     [%.3f, %.3f, %.3f] .. [%.3f, %.3f, %.3f] m\n", s.bounds.lo.x, s.bounds.lo.y,
                s.bounds.lo.z, s.bounds.hi.x, s.bounds.hi.y, s.bounds.hi.z);
  std::printf("textures:   %zu (%.2f MiB)\n", s.textures, double(s.texture_bytes) / (1024.0 * 1024.0));
  std::set<const image::ColorImage*> seen;
  for (const auto& m : scene.materials) {
    if (!m.texture || !seen.insert(m.texture.get()).second) continue;
    std::printf("  %-24s %dx%d %s\n", m.name.c_str(), m.texture->width(), m.texture->height(),
                m.texture_path.c_str());
  }
  for (const std::string& w : import_stats.warnings()) std::printf("warning:    %s\n", w.c_str());
  if (list_objects) {
    for (const auto& o : scene.objects) {
      uint64_t tris = 0;
      for (const auto& p : o.parts) tris += scene.meshes[p.mesh].triangleCount();
      std::printf("  object %u %-20s parts %zu triangles %llu footprint %zu\n", o.id, o.name.c_str(), o.parts.size(),
                  (unsigned long long)tris, o.footprint.size());
    }
  }
}

const RegisterCommand reg("info", [](CLI::App& app) {
  auto spec = std::make_shared<std::string>();
  auto list = std::make_shared<bool>(false);
  auto* cmd = app.add_subcommand("info", "Print a scene's objects, triangles, bounds and textures.");
  cmd->add_option("scene", *spec, "Scene file or builtin:NAME")->required();
  cmd->add_flag("--objects", *list, "List every object");
  cmd->callback([spec, list] { runInfo(*spec, *list); });
});

}  // namespace
}  // namespace farfield::app
