#include "farfield/view/database_modes.h"

#include <filesystem>

#include "farfield/core/error.h"
#include "farfield/runtime/walkthrough.h"
#include "farfield/store/impostor_store.h"

namespace fs = std::filesystem;

namespace farfield::view {
DatabaseModes databaseModes(const std::string& dir) {
  DatabaseModes out;
  out.modes = {"full", "culled"};
  if (dir.empty()) return out;
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw Error(dir, "no impostor database there (a directory written by farfield bake --pipeline or farfield place)");
  if (fs::exists(fs::path(dir) / store::kPlacementIndexFile, ec)) {
    out.kind = DatabaseKind::Placement;
    out.placement = std::make_shared<const store::PlacementIndex>(store::readPlacementIndex(dir));
    out.modes.push_back("placed");
    out.modes.push_back("governed");  // placed under the frame governor (eval/governed_mode.h)
    return out;
  }
  if (!fs::exists(fs::path(dir) / store::kIndexFile, ec))
    throw Error(dir, std::string("holds neither ") + store::kIndexFile + " (farfield bake --pipeline) nor " +
                         store::kPlacementIndexFile + " (farfield place)");
  const store::StoreIndex index = store::readIndex(dir);
  const std::string index_file = (fs::path(dir) / store::kIndexFile).string();
  if (index.pipeline.empty())
    throw Error(index_file, "holds no pipeline data (the viewer needs a store baked with farfield bake --pipeline "
                            "pvs,near-far,single,mmi, or a placement from farfield place)");
  out.kind = DatabaseKind::Pipeline;
  out.streets_file = (fs::path(dir) / index.streets).string();
  // The representations runtime::Walkthrough can open on this store, in the viewer's order.
  using R = runtime::Representation;
  for (R r : {R::Local, R::Visible, R::Smi, R::MmiDynamic, R::Mmi})
    if (runtime::missingStage(index, r).empty()) out.modes.push_back(runtime::representationName(r));
  return out;
}

std::string defaultMode(const DatabaseModes& modes) {
  if (modes.kind == DatabaseKind::Placement) return "placed";  // the promised bound on every frame
  return modes.kind == DatabaseKind::None ? "full" : modes.modes.back();
}

}  // namespace farfield::view
