#include "farfield/view/mode_renderer.h"

#include "farfield/core/check.h"
#include "farfield/core/error.h"
#include "farfield/core/timer.h"
#include "farfield/core/log.h"
#include "farfield/eval/city_on_terrain_mode.h"
#include "farfield/eval/terrain_modes.h"

namespace farfield::view {

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
    if (!settings_.terrain.empty())
      FF_WARN("mode " << mode << " draws the city without the terrain (full and culled draw it under the city)");
    auto walkthrough = std::make_unique<runtime::Walkthrough>(scene_, gpu_scene_, bvh_, renderer_, options);
    walkthrough_ = std::move(walkthrough);
    eval_mode_.reset();
  } else {
    if (mode != "full" && mode != "culled")
      throw Error("mode '" + mode + "'", "unknown; the viewer draws full, culled and the database's representations "
                                         "(local, visible, smi, mmi, mmi-dynamic, placed)");
    std::unique_ptr<eval::Mode> created;
    if (settings_.terrain.empty()) created = eval::createMode(mode, context_);
    else created = std::make_unique<eval::CityOnTerrainMode>("lod-sprite", mode);
    created->prepare(context_);
    eval_mode_ = std::move(created);
    walkthrough_.reset();
  }
  mode_ = mode;
  last_items_.clear();
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
    return frame;
  }
  Stopwatch clock;
  const runtime::FramePlan& plan = walkthrough_->plan(camera);
  last_items_.assign(plan.items.begin(), plan.items.end());
  last_kinds_ = itemKinds(plan, gpu_scene_, uint32_t(scene_.objects.size() + 1));
  const gpu::FrameStats stats = draw(camera, tint);
  frame.cpu_ms = clock.milliseconds();
  frame.gpu_ms = stats.gpu_ms;
  frame.triangles = stats.triangles + plan.report.update_stats.triangles;
  frame.draw_calls = stats.draw_calls + plan.report.update_stats.draw_calls;
  frame.plan = &plan;
  frame.decisions = countDecisions(plan);
  return frame;
}

gpu::FrameStats ModeRenderer::draw(const Camera& camera, bool tint) {
  if (!tint) return renderer_.render(camera, last_items_, target_);
  const std::vector<gpu::DrawItem> tinted = tintedItems(last_items_, last_kinds_, tint_materials_);
  return renderer_.render(camera, tinted, target_);
}

void ModeRenderer::redraw(const Camera& camera, size_t frame_index, bool tint) {
  if (eval_mode_)
    runner_.run(*eval_mode_, camera, frame_index);
  else
    draw(camera, tint);
}

}  // namespace farfield::view
