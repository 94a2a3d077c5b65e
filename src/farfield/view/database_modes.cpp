#include "farfield/view/database_modes.h"

#include <algorithm>
#include <filesystem>

#include "farfield/core/error.h"
#include "farfield/extract/pipeline_options.h"
#include "farfield/store/impostor_store.h"

namespace fs = std::filesystem;

namespace farfield::view {
namespace {
bool contains(const std::vector<std::string>& list, const std::string& item) {
  return std::find(list.begin(), list.end(), item) != list.end();
}
}  // namespace

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
  // The rules of runtime::Walkthrough's constructor: which stage each representation needs.
  const bool pvs_baked = contains(index.pipeline, extract::kStagePvs) && !contains(index.online, extract::kStagePvs);
  if (contains(index.pipeline, extract::kStageNearFar)) out.modes.push_back("local");
  if (pvs_baked) out.modes.push_back("visible");
  if (contains(index.pipeline, extract::kStageSingle)) out.modes.push_back("smi");
  if (contains(index.pipeline, extract::kStageMmi)) {
    out.modes.push_back("mmi-dynamic");
    out.modes.push_back("mmi");
  }
  return out;
}

std::string defaultMode(const DatabaseModes& modes) {
  return modes.kind == DatabaseKind::None ? "full" : modes.modes.back();
}

}  // namespace farfield::view
