#include "farfield/runtime/database.h"

#include <filesystem>

#include "farfield/core/error.h"

namespace fs = std::filesystem;

namespace farfield::runtime {

OpenStore openStore(const std::string& dir, const scene::Scene& scene, const std::string& lookup_option) {
  OpenStore out;
  out.index = store::readIndex(dir);
  out.index_file = (fs::path(dir) / store::kIndexFile).string();
  if (out.index.scene_objects != scene.objects.size())
    throw Error(out.index_file, "was baked for a scene with " + std::to_string(out.index.scene_objects) +
                                    " objects, but this scene has " + std::to_string(scene.objects.size()));
  out.graph = urban::StreetGraph::load((fs::path(dir) / out.index.streets).string());
  out.locator = urban::CellLocator(
      out.graph, urban::parseCellLookup(lookup_option.empty() ? out.index.cell_lookup : lookup_option,
                                        lookup_option.empty() ? out.index_file + ": cell_lookup" : "cell_lookup"));
  for (const store::CellEntry& e : out.index.cells)
    if (e.half_edge >= out.graph.halfEdgeCount())
      throw Error(out.index_file,
                  "cell " + std::to_string(e.half_edge) + " is not a half-edge of " + out.index.streets);
  return out;
}

}  // namespace farfield::runtime
