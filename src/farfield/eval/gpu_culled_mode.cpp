#include "farfield/eval/gpu_culled_mode.h"

#include "farfield/core/error.h"

namespace farfield::eval {
namespace {

bool onOff(const ModeContext& context, const std::string& key, bool fallback, const std::string& mode_name) {
  const std::string value = context.option(key, fallback ? "on" : "off");
  if (value == "on") return true;
  if (value == "off") return false;
  throw Error("mode '" + mode_name + "'", key + " must be on or off, got '" + value + "'");
}

}  // namespace

gpu::GpuCullOptions gpuCullOptions(const ModeContext& context, const std::string& mode_name) {
  gpu::GpuCullOptions options;
  options.occlusion = onOff(context, "gpu_occlusion", options.occlusion, mode_name);
  options.cone = onOff(context, "gpu_cones", options.cone, mode_name);
  options.compact = onOff(context, "gpu_compact", options.compact, mode_name);
  options.refine_history = onOff(context, "gpu_refine_history", options.refine_history, mode_name);
  options.stage_times = onOff(context, "gpu_stage_times", options.stage_times, mode_name);
  return options;
}

GpuCullRun::GpuCullRun(const ModeContext& context, const gpu::GpuCullOptions& options)
    : culler_(std::make_unique<gpu::GpuCuller>(context.arena(), options)), arena_build_s_(context.arena_slot->build_s) {}

void GpuCullRun::draw(FrameContext& frame) {
  gpu::RenderTarget& target = frame.beginOwnPass();
  path_frame_of_.push_back(frame.pathFrame());
  frame.addStats(culler_->draw(frame.camera(), target, gpu::RenderMode::Shaded, frame.renderer().light()));
}

void GpuCullRun::collect() {
  for (const gpu::GpuCullStats& s : culler_->finishedStats()) {
    latest_[path_frame_of_.at(s.frame)] = s;
    frames_ += 1.0;
    early_ += s.drawn_early;
    late_ += s.drawn_late;
    frustum_ += s.frustum_culled;
    cone_ += s.cone_culled;
    occluded_ += s.occlusion_culled;
    commands_ += s.commands;
    triangles_ += double(s.triangles);
  }
  for (const gpu::GpuStageTimes& t : culler_->finishedStageTimes()) {
    for (size_t i = 0; i < t.ms.size(); ++i) stage_ms_[i] += t.ms[i];
    stage_frames_ += 1.0;
  }
}

std::optional<gpu::FrameStats> GpuCullRun::lateFrameStats(size_t path_frame) {
  collect();
  const auto it = latest_.find(path_frame);
  if (it == latest_.end()) return std::nullopt;
  gpu::FrameStats stats;
  stats.triangles = it->second.triangles;
  stats.objects = it->second.objects;
  return stats;
}

std::map<std::string, double> GpuCullRun::info() const {
  std::map<std::string, double> out;
  const gpu::SceneArena& arena = culler_->arena();
  out["arena_clusters"] = double(arena.clusters().size());
  out["arena_instances"] = double(arena.instances().size());
  out["arena_material_groups"] = double(arena.groups().size());
  out["arena_gpu_bytes"] = double(arena.gpuBytes());
  out["arena_build_s"] = arena_build_s_;
  out["indirect_count"] = culler_->indirectCount() ? 1.0 : 0.0;
  if (frames_ > 0.0) {
    out["gpu_clusters_drawn_early"] = early_ / frames_;
    out["gpu_clusters_drawn_late"] = late_ / frames_;
    out["gpu_frustum_culled"] = frustum_ / frames_;
    out["gpu_cone_culled"] = cone_ / frames_;
    out["gpu_occlusion_culled"] = occluded_ / frames_;
    out["gpu_draw_commands"] = commands_ / frames_;
    out["gpu_triangles"] = triangles_ / frames_;
  }
  if (stage_frames_ > 0.0) {
    for (size_t i = 0; i < stage_ms_.size(); ++i)
      out[std::string("gpu_stage_") + gpu::kGpuCullStages[i] + "_ms"] = stage_ms_[i] / stage_frames_;
    out["gpu_stage_frames"] = stage_frames_;
  }
  return out;
}

GpuCulledMode::GpuCulledMode(const ModeContext& context) : options_(gpuCullOptions(context, "culled")) {}

void GpuCulledMode::prepare(const ModeContext& context) { run_.emplace(context, options_); }

}  // namespace farfield::eval
