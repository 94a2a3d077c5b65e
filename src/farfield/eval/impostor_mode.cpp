// Local model + cell impostor per frame (Sillion et al. 1997, section 3: "always draw the combination of the
// impostors of the current cell and its local model, to obtain a view of the entire model"), through the walkthrough
// of the pipeline's single stage.
//
// Why registerImpostorModes() instead of a static RegisterMode object: the eval library is static and nothing in an
// executable refers to this file's symbols except through the registry, so the linker would drop the object file
// together with its static initialiser and the modes would silently be missing. A function the executable calls
// pulls the file in for certain.
#include "farfield/eval/impostor_mode.h"

#include <algorithm>
#include <filesystem>

#include "farfield/core/error.h"
#include "farfield/eval/dynamic_modes.h"
#include "farfield/eval/mmi_mode.h"
#include "farfield/eval/mode_options.h"
#include "farfield/extract/pipeline_options.h"
#include "farfield/store/impostor_store.h"

namespace farfield::eval {

void registerImpostorModes() {
  registerMode("depth-mesh",
               "local model (blocks touching the street) + the cell's textured depth-mesh impostor (Sillion 1997) "
               "where it keeps the bound; --impostors DIR from bake --technique depth-mesh",
               [](const ModeContext& c) { return std::make_unique<ImpostorMode>(extract::kDepthMesh, c); });
  registerMode("grid-mesh",
               "local model + the cell's regular-grid mesh impostor (baseline) where it keeps the bound; --impostors "
               "DIR from bake --technique grid-mesh",
               [](const ModeContext& c) { return std::make_unique<ImpostorMode>(extract::kGridMesh, c); });
  registerMmiModes();
  registerDynamicModes();
}

ImpostorMode::ImpostorMode(std::string technique, const ModeContext& context) : technique_(std::move(technique)) {
  runtime::WalkthroughOptions& o = options_;
  o.representation = runtime::Representation::Smi;
  std::string key = technique_;
  std::replace(key.begin(), key.end(), '-', '_');
  o.database = context.option(key + "_dir", context.option("impostor_dir"));
  if (o.database.empty())
    throw Error("mode '" + technique_ + "'", "needs an impostor store: farfield bench --impostors DIR (or "
                                             "--mode-option impostor_dir=DIR), baked with farfield bake --technique " +
                                                 technique_);
  o.gpu_budget_bytes = mebibytesOption(context, "gpu_budget_mb", o.gpu_budget_bytes);
  o.read_ahead = switchOption(context, "read_ahead", true);
  o.memory_budget_bytes = mebibytesOption(context, "memory_budget_mb", 0);
  o.streaming_csv = context.option("streaming_csv");
  o.object_ids = choiceOption(context, "impostor_ids", "object", {"object", "layer"}) == "object";
  o.cell_lookup = context.option("cell_lookup");
  if (!o.cell_lookup.empty()) urban::parseCellLookup(o.cell_lookup, "--mode-option cell_lookup");
  o.error_px = numberOption(context, "error_px", 0.0, 0.0);
  geometry_.emplace(context, technique_);
  geometry_->configure(o);
}

ImpostorMode::~ImpostorMode() = default;

void ImpostorMode::prepare(const ModeContext& context) {
  const store::StoreIndex index = store::readIndex(options_.database);
  const std::string index_file = (std::filesystem::path(options_.database) / store::kIndexFile).string();
  if (index.pipeline.empty() && !index.techniques.empty())
    throw Error(index_file, "holds Sillion cell impostors of a store version " + std::to_string(index.version) +
                                " bake, which the " + technique_ + " mode no longer reads (the bake became the "
                                "pipeline's single stage): re-bake with farfield bake SCENE --technique " +
                                technique_ + " -o " + options_.database);
  if (std::find(index.pipeline.begin(), index.pipeline.end(), extract::kStageSingle) != index.pipeline.end()) {
    const extract::PipelineOptions baked = extract::pipelineOptionsFromJson(
        index.options.contains("pipeline") ? index.options["pipeline"] : nlohmann::json::object(),
        index_file + ": options.pipeline", index.version);
    if (baked.mesh != extract::techniqueMesh(technique_, "mode '" + technique_ + "'"))
      throw Error(index_file, std::string("its single meshes are ") + extract::layerMeshName(baked.mesh) +
                                  " meshes; the " + technique_ + " mode needs a store baked with --technique " +
                                  technique_ + " (or --layer-mesh " +
                                  extract::layerMeshName(extract::techniqueMesh(technique_)) + ")");
  }
  options_.width = context.width;
  options_.height = context.height;
  // The walkthrough checks the rest: the scene, the single stage (Smi), the stage lists.
  geometry_->prepare(context);
  walkthrough_ = std::make_unique<runtime::Walkthrough>(*context.scene, *context.gpu_scene, *context.bvh,
                                                        *context.renderer, options_);
}

void ImpostorMode::frame(FrameContext& frame) {
  const runtime::FramePlan& plan = walkthrough_->plan(frame.camera());
  geometry_->submit(frame, plan);
}

std::map<std::string, double> ImpostorMode::info() const {
  std::map<std::string, double> info = walkthrough_ ? walkthrough_->statistics() : std::map<std::string, double>{};
  info.merge(geometry_->info());
  return info;
}

}  // namespace farfield::eval
