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

GpuRunOptions gpuRunOptions(const ModeContext& context, const std::string& mode_name,
                            const std::string& occlusion_default) {
  GpuRunOptions options;
  gpu::GpuCullOptions& cull = options.cull;
  const std::string occlusion = context.option("gpu_occlusion", occlusion_default);
  if (occlusion != "on" && occlusion != "off" && occlusion != "auto")
    throw Error("mode '" + mode_name + "'", "gpu_occlusion must be on, off or auto, got '" + occlusion + "'");
  cull.occlusion = occlusion != "off";
  options.occlusion_auto = occlusion == "auto";
  cull.cone = onOff(context, "gpu_cones", cull.cone, mode_name);
  cull.compact = onOff(context, "gpu_compact", cull.compact, mode_name);
  cull.refine_history = onOff(context, "gpu_refine_history", cull.refine_history, mode_name);
  cull.stage_times = onOff(context, "gpu_stage_times", cull.stage_times, mode_name);
  return options;
}

GpuCullRun::GpuCullRun(const ModeContext& context, const GpuRunOptions& options)
    : culler_(std::make_unique<gpu::GpuCuller>(context.arena(), options.cull)),
      arena_build_s_(context.arena_slot->build_s) {
  occlusion_auto_ = options.occlusion_auto;
}

void GpuCullRun::draw(FrameContext& frame) {
  gpu::RenderTarget& target = frame.beginOwnPass();
  if (occlusion_auto_) {
    // One choice per kind of frame: a governor's levels (sizes, simplified levels) differ in what the test saves.
    last_kind_ = std::make_tuple(target.width(), target.height(), culler_->options().lod_error_px);
    runtime::FasterVariant* choice = nullptr;
    bool on = forced_occlusion_.value_or(true);
    if (!forced_occlusion_) {
      choice = &occlusion_choices_.try_emplace(last_kind_, 0).first->second;
      on = choice->decide(path_frame_of_.size(), probe_room_) == 0;
    }
    culler_->setOcclusion(on);
    occlusion_frames_ += on ? 1.0 : 0.0;
    chooser_of_.push_back(choice);
  }
  path_frame_of_.push_back(frame.pathFrame());
  frame.addStats(culler_->draw(frame.camera(), target, gpu::RenderMode::Shaded, frame.renderer().light()));
}

void GpuCullRun::frameMeasured(size_t path_frame, double wall_ms) {
  if (!occlusion_auto_) return;
  // The last frame drawn for it: a governor's calibration draws a path frame several times, untimed.
  for (size_t i = path_frame_of_.size(); i-- > 0 && path_frame_of_.size() - i <= 64;) {
    if (path_frame_of_[i] == path_frame) {
      if (chooser_of_[i]) chooser_of_[i]->measured(i, wall_ms);
      return;
    }
  }
}

bool GpuCullRun::startOcclusionFrom(double on_ms, double off_ms) {
  if (!occlusion_auto_) return culler_->options().occlusion;
  runtime::FasterVariant& choice = occlusion_choices_.try_emplace(last_kind_, 0).first->second;
  choice.startFrom(on_ms, off_ms);
  return choice.kept() == 0;
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
  if (occlusion_auto_) {
    const double drawn = double(path_frame_of_.size());
    out["gpu_occlusion_auto"] = 1.0;
    out["gpu_occlusion_frames"] = drawn > 0.0 ? occlusion_frames_ / drawn : 0.0;
    out["gpu_occlusion_kinds"] = double(occlusion_choices_.size());
    double probes = 0.0, switches = 0.0, early = 0.0, started = 0.0, held = 0.0;
    size_t most = 0;
    for (const auto& [key, choice] : occlusion_choices_) {
      probes += double(choice.probes());
      held += double(choice.probesHeld());
      switches += double(choice.switches());
      early += double(choice.earlyProbes());
      started += double(choice.starts());
      const size_t frames = choice.framesOf(0) + choice.framesOf(1);
      if (frames > most) {
        most = frames;
        out["gpu_occlusion_kept"] = choice.kept() == 0 ? 1.0 : 0.0;  // the choice of the kind drawn most
      }
    }
    out["gpu_occlusion_probes"] = probes;
    out["gpu_occlusion_switches"] = switches;
    out["gpu_occlusion_early_probes"] = early;
    out["gpu_occlusion_started"] = started;
    out["gpu_occlusion_held"] = held;
  }
  if (stage_frames_ > 0.0) {
    for (size_t i = 0; i < stage_ms_.size(); ++i)
      out[std::string("gpu_stage_") + gpu::kGpuCullStages[i] + "_ms"] = stage_ms_[i] / stage_frames_;
    out["gpu_stage_frames"] = stage_frames_;
  }
  return out;
}

GpuCulledMode::GpuCulledMode(const ModeContext& context) : options_(gpuRunOptions(context, "culled")) {}

void GpuCulledMode::prepare(const ModeContext& context) { run_.emplace(context, options_); }

}  // namespace farfield::eval
