#include "farfield/eval/plan_geometry.h"

#include "farfield/eval/mode_options.h"

namespace farfield::eval {

PlanGeometry::PlanGeometry(const ModeContext& context, const std::string& mode_name) {
  gpu_ = choiceOption(context, "geometry", "gpu", {"gpu", "cpu"}) == "gpu";
  const bool occlusion = switchOption(context, "occlusion", true);
  if (gpu_) {
    gpu_options_ = gpuRunOptions(context, mode_name, "auto");
    if (!occlusion) {
      gpu_options_.cull.occlusion = false;
      gpu_options_.occlusion_auto = false;
    }
  } else if (occlusion) {
    occlusion_.emplace(occluderShareOption(context, mode_name));
  }
}

void PlanGeometry::prepare(const ModeContext& context) {
  gpu_scene_ = context.gpu_scene;
  if (gpu_) run_.emplace(context, gpu_options_);
}

void PlanGeometry::submitObjects(FrameContext& frame, std::span<const uint32_t> ids) {
  if (gpu_) {
    run_->culler().setObjects(ids);
    ++uploads_;
    run_->draw(frame);
    return;
  }
  // GpuScene::appendDrawItems takes an empty list as "all objects".
  if (ids.empty()) return;
  if (!occlusion_) {
    gpu_scene_->appendDrawItems(ids, frame.items(), frame.camera());
    return;
  }
  candidates_.clear();
  bounds_.clear();
  gpu_scene_->appendDrawItems(ids, candidates_, frame.camera(), &bounds_);
  occlusion_->run(frame, candidates_, bounds_);
}

void PlanGeometry::submit(FrameContext& frame, const runtime::FramePlan& plan) {
  if (!gpu_) {
    submitPlan(frame, plan, occlusion_ ? &*occlusion_ : nullptr);
    return;
  }
  if (plan.geometry_version != version_) {
    run_->culler().setObjects(plan.geometry_objects);
    version_ = plan.geometry_version;
    ++uploads_;
  }
  run_->draw(frame);
  frame.items().insert(frame.items().end(), plan.items.begin() + std::ptrdiff_t(plan.geometry_items),
                       plan.items.end());
}

void PlanGeometry::frameMeasured(size_t path_frame, double wall_ms) {
  if (run_) run_->frameMeasured(path_frame, wall_ms);
}

std::optional<gpu::FrameStats> PlanGeometry::lateFrameStats(size_t path_frame) {
  return run_ ? run_->lateFrameStats(path_frame) : std::nullopt;
}

std::map<std::string, double> PlanGeometry::info() const {
  std::map<std::string, double> out = run_ ? run_->info() : occlusion_ ? occlusion_->info() : std::map<std::string, double>{};
  out["geometry_gpu"] = gpu_ ? 1.0 : 0.0;
  if (gpu_) out["geometry_uploads"] = double(uploads_);
  return out;
}

}  // namespace farfield::eval
