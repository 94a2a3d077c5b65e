// The Table 1 modes of Decoret et al. 1999 over a pipeline store: option parsing and the Walkthrough they adapt.
#include "farfield/eval/mmi_mode.h"

#include <algorithm>
#include <cmath>
#include <variant>
#include <stdexcept>

#include "farfield/core/error.h"
#include "farfield/eval/impostor_mode.h"
#include "farfield/eval/mode_options.h"

namespace farfield::eval {

void registerMmiModes() {
  const auto add = [](runtime::Representation kind, const char* description) {
    registerMode(runtime::representationName(kind), description, [kind](const ModeContext& c) {
      return std::make_unique<MmiMode>(kind, c);
    });
  };
  add(runtime::Representation::Local, "the cell's near geometry only, frustum-culled: upper bound of the frame rate "
                             "(Decoret 1999); --impostors DIR from bake --pipeline");
  add(runtime::Representation::Visible, "the cell's potentially visible set, frustum-culled (Decoret 1999); --impostors DIR");
  add(runtime::Representation::Smi, "near geometry + single-mesh impostor of the far objects (Decoret 1999); --impostors DIR");
  add(runtime::Representation::Mmi, "near geometry + multi-mesh impostor, one mesh per layer (Decoret 1999); --impostors DIR");
  add(runtime::Representation::Placed, "layered impostors placed per conservative problem view under a frame budget "
                                       "(Jeschke 2005); --impostors DIR from farfield place");
  add(runtime::Representation::MmiDynamic, "mmi with dynamic updates of the front-most layers under a frame budget "
                                  "(Decoret 1999, 5.5); --impostors DIR, --mode-option frame_budget_ms=MS");
}

MmiMode::MmiMode(runtime::Representation representation, const ModeContext& context) {
  runtime::WalkthroughOptions& o = options_;
  o.representation = representation;
  o.database = context.option("mmi_dir", context.option("impostor_dir"));
  if (o.database.empty())
    throw Error(std::string("mode '") + runtime::representationName(representation) + "'",
                "needs a pipeline store: farfield bench --impostors DIR (or --mode-option impostor_dir=DIR), baked "
                "with farfield bake --pipeline pvs,near-far,single,mmi (placed: farfield place)");
  o.gpu_budget_bytes = mebibytesOption(context, "gpu_budget_mb", o.gpu_budget_bytes);
  o.read_ahead = switchOption(context, "read_ahead", true);
  o.memory_budget_bytes = mebibytesOption(context, "memory_budget_mb", 0);
  o.streaming_csv = context.option("streaming_csv");
  o.object_ids = choiceOption(context, "impostor_ids", "object", {"object", "layer"}) == "object";
  o.dynamic.object_ids = o.object_ids;
  o.cell_lookup = context.option("cell_lookup");
  if (!o.cell_lookup.empty()) urban::parseCellLookup(o.cell_lookup, "--mode-option cell_lookup");
  o.frame_budget_ms = numberOption(context, "frame_budget_ms", o.frame_budget_ms, 0.0);
  o.dynamic_error_px = numberOption(context, "dynamic_error_px", o.dynamic_error_px, 0.0);
  o.dynamic.resolution = intOption(context, "dynamic_resolution", 0, 0, 16384);  // DynamicImpostor's range
  o.dynamic.grid_px = intOption(context, "dynamic_grid_px", o.dynamic.grid_px, 1, 16384);
  o.max_updates = countOption(context, "dynamic_max_updates", o.max_updates);
  o.min_lifetime_frames = numberOption(context, "dynamic_min_lifetime", o.min_lifetime_frames, 0.0);
  o.error_px = numberOption(context, "error_px", 0.0, 0.0);
  o.layer_tiles = switchOption(context, "layer_tiles", true);
  o.coarser_impostors = switchOption(context, "coarser_impostors", true);
  o.placed_read_ahead_frames = countOption(context, "read_ahead_frames", o.placed_read_ahead_frames, 0);
  read_ahead_ms_ = numberOption(context, "read_ahead_ms", 0.0, 0.0);
  geometry_.emplace(context, runtime::representationName(representation));
  geometry_->configure(o);
}

MmiMode::~MmiMode() = default;

void MmiMode::prepare(const ModeContext& context) {
  options_.width = context.width;
  options_.height = context.height;
  geometry_->prepare(context);
  walkthrough_ = std::make_unique<runtime::Walkthrough>(*context.scene, *context.gpu_scene, *context.bvh, *context.renderer,
                                               options_);
}

void MmiMode::frame(FrameContext& frame) {
  const runtime::FramePlan& plan = walkthrough_->plan(frame.camera(), [&] { frame.beginOwnPass(); });
  geometry_->submit(frame, plan);
  if (plan.report.updates > 0) frame.addStats(plan.report.update_stats);
  last_drew_impostors_ = std::any_of(plan.layers.begin(), plan.layers.end(), [](const runtime::LayerDecision& d) {
    return !std::holds_alternative<runtime::LayerAsGeometry>(d) && !std::holds_alternative<runtime::ClusterAsGeometry>(d);
  });
  impostor_frames_[frame.pathFrame()] = last_drew_impostors_;
  if (read_ahead_ms_ > 0.0) walkthrough_->loadAhead(frame.camera(), read_ahead_ms_);
}

std::map<std::string, double> MmiMode::info() const {
  // The walkthrough reports its bound (error_bound_px) for the representations that draw impostors only.
  std::map<std::string, double> info = walkthrough_ ? walkthrough_->statistics() : std::map<std::string, double>{};
  info.merge(geometry_->info());
  if (drawsImpostors()) addImpostorFrames(impostor_frames_, info);
  return info;
}

}  // namespace farfield::eval
