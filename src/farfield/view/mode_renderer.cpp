#include "farfield/view/mode_renderer.h"

#include <cstdio>
#include <filesystem>

#include "farfield/core/check.h"
#include "farfield/core/error.h"
#include "farfield/core/log.h"
#include "farfield/eval/city_on_terrain_mode.h"
#include "farfield/eval/impostor_mode.h"
#include "farfield/eval/terrain_modes.h"
#include "farfield/store/placement_store.h"

namespace fs = std::filesystem;

namespace farfield::view {

class ModeRenderer::PlanFrame final : public eval::Mode {
 public:
  explicit PlanFrame(ModeRenderer& owner) : owner_(owner) {}
  std::string name() const override { return owner_.mode_; }
  bool replan = true;
  bool tint = false;
  void frame(eval::FrameContext& frame) override {
    ModeRenderer& o = owner_;
    if (replan) {
      const runtime::FramePlan& plan = o.walkthrough_->plan(frame.camera(), [&] { frame.beginOwnPass(); });
      o.last_plan_ = &plan;
      o.last_items_.assign(plan.items.begin(), plan.items.end());
      o.last_kinds_ = itemKinds(plan, o.gpu_scene_, uint32_t(o.scene_.objects.size() + 1));
      if (plan.geometry_version != o.geometry_version_) {
        o.geometry_->culler().setObjects(plan.geometry_objects);
        o.geometry_version_ = plan.geometry_version;
      }
      if (plan.report.updates > 0) frame.addStats(plan.report.update_stats);
    }
    o.geometry_->draw(frame);
    if (tint) {
      o.tinted_ = tintedItems(o.last_items_, o.last_kinds_, o.tint_materials_);
      frame.items() = o.tinted_;
    } else {
      frame.items() = o.last_items_;
    }
    // After the geometry's draws are issued, while the GPU works: the next cells' (or impostors') uploads.
    if (replan && o.settings_.load_ahead_ms > 0.0) o.walkthrough_->loadAhead(frame.camera(), o.settings_.load_ahead_ms);
  }
  std::optional<gpu::FrameStats> lateFrameStats(size_t path_frame) override {
    return owner_.geometry_->lateFrameStats(path_frame);
  }
  void frameMeasured(size_t path_frame, double wall_ms) override {
    owner_.geometry_->frameMeasured(path_frame, wall_ms);
  }

 private:
  ModeRenderer& owner_;
};

ModeRenderer::ModeRenderer(const scene::Scene& scene, const gpu::GpuScene& gpu_scene, const scene::Bvh& bvh,
                           gpu::Renderer& renderer, gpu::RenderTarget& target, ModeSettings settings)
    : scene_(scene),
      gpu_scene_(gpu_scene),
      bvh_(bvh),
      renderer_(renderer),
      target_(target),
      settings_(std::move(settings)),
      runner_(renderer, target) {
  context_.scene = &scene;
  context_.gpu_scene = &gpu_scene;
  context_.bvh = &bvh;
  context_.renderer = &renderer;
  context_.width = target.width();
  context_.height = target.height();
  if (!settings_.terrain.empty()) {
    context_.options["terrain"] = settings_.terrain;
    context_.options["terrain_scale"] = std::to_string(settings_.terrain_scale);
  }
}

ModeRenderer::~ModeRenderer() {
  // The terrain's GPU buffers go while the context is current (the run outlives the modes otherwise).
  eval_mode_.reset();
  plan_frame_.reset();
  geometry_.reset();
  if (!settings_.terrain.empty()) eval::currentTerrainRun().reset();
}

void ModeRenderer::select(const std::string& mode) {
  if (const auto representation = runtime::representationFromName(mode)) {
    runtime::WalkthroughOptions options;
    options.database = settings_.database;
    options.representation = *representation;
    options.error_px = settings_.error_px;
    options.gpu_budget_bytes = settings_.gpu_budget_bytes;
    options.width = target_.width();
    options.height = target_.height();
    options.geometry_items = false;  // the plan's objects, drawn by the GPU-driven frame
    if (!settings_.terrain.empty())
      FF_WARN("mode " << mode << " draws the city without the terrain (full and culled draw it under the city)");
    auto walkthrough = std::make_unique<runtime::Walkthrough>(scene_, gpu_scene_, bvh_, renderer_, options);
    walkthrough_ = std::move(walkthrough);
    eval_mode_.reset();
    // Occlusion culling as the bench's walkthrough modes have it: on or off, whichever the frames measure faster.
    if (!geometry_) geometry_.emplace(context_, eval::GpuRunOptions{.cull = {}, .occlusion_auto = true});
    geometry_version_ = ~uint64_t(0);
    geometry_->culler().resetHistory();
    plan_frame_ = std::make_unique<PlanFrame>(*this);
  } else if (mode == "governed") {
    eval_mode_ = governedMode();
    walkthrough_.reset();
  } else {
    if (mode != "full" && mode != "culled")
      throw Error("mode '" + mode + "'", "unknown; the viewer draws full, culled, the database's representations "
                                         "(local, visible, smi, mmi, mmi-dynamic, placed) and governed");
    std::unique_ptr<eval::Mode> created;
    if (settings_.terrain.empty()) created = eval::createMode(mode, context_);
    else created = std::make_unique<eval::CityOnTerrainMode>(settings_.terrain_technique, mode);
    created->prepare(context_);
    eval_mode_ = std::move(created);
    walkthrough_.reset();
  }
  mode_ = mode;
  last_items_.clear();
  last_plan_ = nullptr;
}

std::unique_ptr<eval::Mode> ModeRenderer::governedMode() {
  if (settings_.database.empty() || !fs::exists(fs::path(settings_.database) / store::kPlacementIndexFile))
    throw Error("mode 'governed'", "needs a placement database (farfield place ... -o DIR; --impostors DIR)");
  if (!(settings_.t_max_ms > 0.0))
    throw Error("mode 'governed'", "needs a frame budget: --tmax MS (or t_max in the panel) above 0");
  if (!settings_.terrain.empty())
    FF_WARN("mode governed draws the city without the terrain (full and culled draw it under the city)");
  // The promised bound the governor's levels are relative to: the viewer's, else the placement's own.
  double bound_px = settings_.error_px;
  if (!(bound_px > 0.0)) {
    const nlohmann::json options = store::readPlacementIndex(settings_.database).options;
    if (!options.contains("error_px") || !options["error_px"].is_number())
      throw Error(settings_.database + "/" + store::kPlacementIndexFile,
                  "options.error_px is missing: give the viewer an error bound (--error-px)");
    bound_px = options["error_px"].get<double>();
  }
  governed_bound_px_ = bound_px;
  eval::ModeContext context = context_;  // shares the run's arena
  const auto number = [](double v) {
    char text[32];
    std::snprintf(text, sizeof(text), "%.17g", v);
    return std::string(text);
  };
  context.options["governed"] = "placed";
  context.options["impostor_dir"] = settings_.database;
  context.options["governor_t_max_ms"] = number(settings_.t_max_ms);
  context.options["governor_error_px"] = number(bound_px);
  if (settings_.error_px > 0.0) context.options["error_px"] = number(settings_.error_px);
  // The governed mode asks for the arena's simplified levels; an arena made before without them (culled or a
  // walkthrough mode selected first) stays, and it governs without them (eval/governed_mode.cpp says so).
  if (!context.arena_slot->arena)
    FF_INFO("mode governed: making the scene's arena with its simplified levels (meshopt_simplify per mesh; about "
            "2.5x the time of the arena alone)");
  eval::registerImpostorModes();  // placed is one of them (registering again replaces the same entries)
  std::unique_ptr<eval::Mode> created = eval::createMode("governed", context);
  created->prepare(context);
  return created;
}

void ModeRenderer::setTMaxMs(double t_max_ms) {
  if (t_max_ms == settings_.t_max_ms) return;
  settings_.t_max_ms = t_max_ms;
  if (mode_ == "governed") select("governed");
}

ViewFrame ModeRenderer::render(const Camera& camera, size_t frame_index, bool tint) {
  FF_CHECK(eval_mode_ || walkthrough_);
  ViewFrame frame;
  if (eval_mode_) {
    const eval::FrameRecord record = runner_.run(*eval_mode_, camera, frame_index);
    frame.cpu_ms = record.wall_ms;
    frame.gpu_ms = record.gpu_ms;
    frame.triangles = record.triangles;
    frame.draw_calls = record.draw_calls;
    frame.governance = eval_mode_->governance(frame_index);
    if (frame.governance) frame.kept_bound_px = governed_bound_px_ * frame.governance->bound_scale;
    return frame;
  }
  plan_frame_->replan = true;
  plan_frame_->tint = tint;
  const eval::FrameRecord record = runner_.run(*plan_frame_, camera, frame_index);
  frame.cpu_ms = record.wall_ms;
  frame.gpu_ms = record.gpu_ms;
  frame.triangles = record.triangles;
  frame.draw_calls = record.draw_calls;
  frame.plan = last_plan_;
  frame.decisions = countDecisions(*last_plan_);
  return frame;
}

void ModeRenderer::redraw(const Camera& camera, size_t frame_index, bool tint) {
  if (eval_mode_) {
    runner_.run(*eval_mode_, camera, frame_index);
    return;
  }
  plan_frame_->replan = false;
  plan_frame_->tint = tint;
  runner_.run(*plan_frame_, camera, frame_index);
}

}  // namespace farfield::view
