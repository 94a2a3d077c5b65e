// The crowd runtime's GPU path (issue 45): the runtime's models as the GPU crowd's, the frame set up for a policy
// (Mixed's geometry budget, in triangles or in milliseconds from the skinned draws timed frames later), and the
// GPU's lists drawn by indirect draws, with or without shadows.
#include <algorithm>
#include <iterator>
#include <limits>
#include <string>

#include "farfield/core/error.h"
#include "farfield/runtime/crowd_runtime.h"

namespace farfield::runtime {
namespace {

// Where model m's level l of the camera's (or the casters') geometry list lies: its records in the list buffer and
// its command (gpu::GpuCrowd's layout; without levels of detail, the whole list at level 0).
struct ListRange {
  size_t offset = 0, bytes = 0, command = 0;
};
ListRange geometryRange(const gpu::GpuCrowd& crowd, size_t m, size_t level, bool caster) {
  if (crowd.levelScale() > 0.0f)
    return {crowd.levelListOffset(m, level, caster), crowd.levelCapacity() * sizeof(gpu::CrowdAgentGpu),
            crowd.levelCommand(m, level, caster)};
  const size_t list = crowd.levelCommand(m, 0, caster);  // level 0's command is the list's own
  return {crowd.listOffset(list), crowd.listBytes(), list};
}
size_t drawnLevels(const gpu::GpuCrowd& crowd, size_t m) { return crowd.levelScale() > 0.0f ? crowd.levelCount(m) : 1; }

}  // namespace

std::vector<gpu::GpuCrowdModel> CrowdRuntime::gpuCrowdModels(float nominal_speed) const {
  std::vector<gpu::GpuCrowdModel> out;
  for (const Model& m : models_) {
    const impostor::ViewGrid& grid = m.impostor->grid;
    if (grid.octahedral) throw Error("crowd runtime", "the GPU crowd does not take octahedral atlases yet");
    gpu::GpuCrowdModel g;
    g.centre = m.centre;
    g.radius = m.radius;
    g.stride_m = nominal_speed * m.cycle_s;
    g.palette_poses = uint32_t(options_.palette_poses);
    g.frames = uint32_t(m.choice.frames);
    g.azimuths = uint32_t(grid.azimuths);
    g.elevations = uint32_t(grid.elevations);
    g.max_elevation = grid.max_elevation;
    g.geometry_indices = m.gpu->indexCount();
    g.geometry_first_index = 0;
    for (size_t l = 1; l < m.gpu->levelCount() && l < m.level_m.size(); ++l)
      g.levels.push_back({m.gpu->indexCount(l), m.gpu->firstIndex(l), float(m.level_m[l])});
    out.push_back(g);
  }
  return out;
}

std::vector<float> CrowdRuntime::prepareGpuCrowd(gpu::GpuCrowd& crowd, const Camera& camera, CrowdPolicy policy) {
  if (crowd.modelCount() != models_.size())
    throw Error("crowd runtime", "a GPU crowd of " + std::to_string(crowd.modelCount()) + " models for " +
                                     std::to_string(models_.size()));
  std::vector<float> switches(models_.size());
  for (size_t m = 0; m < models_.size(); ++m)
    switches[m] = policy == CrowdPolicy::Geometry ? std::numeric_limits<float>::max()
                  : policy == CrowdPolicy::Impostor ? -1.0f
                                                    : float(switchDistances(m, camera).both());
  uint64_t budget = 0;
  if (policy == CrowdPolicy::Mixed) {
    budget = options_.max_geometry_triangles;
    if (options_.geometry_ms > 0.0) {
      collectGpuGeometryMs(crowd);
      const uint64_t in_time = std::max<uint64_t>(triangle_rate_.trianglesFor(options_.geometry_ms), 1);
      budget = budget > 0 ? std::min(budget, in_time) : in_time;
    }
  }
  crowd.setGeometryBudget(budget);
  // Levels of detail as levelFor chooses them (Mixed only).
  crowd.setLevelScale(policy == CrowdPolicy::Mixed && options_.geometry_lod_px > 0.0
                          ? float(options_.geometry_lod_px / focalOf(camera))
                          : 0.0f);
  return switches;
}

CrowdFrameStats CrowdRuntime::drawGpuLists(const Camera& camera, gpu::GpuCrowd& crowd,
                                           const gpu::LightSettings& light) {
  CrowdFrameStats stats;
  stats.budget_triangles = crowd.geometryBudget();
  const size_t command = sizeof(gpu::GpuCrowdCommand);
  // The skinned agents first, timed under a budget in milliseconds (read frames later with the lists' sizes), then
  // the impostors.
  const bool timed = options_.geometry_ms > 0.0 && crowd.geometryBudget() > 0;
  if (timed) {
    ++gpu_frame_;
    crowd.captureCommands(gpu_frame_);
    if (!gpu_geometry_timer_) gpu_geometry_timer_ = std::make_unique<gpu::LateTimer>();
    gpu_geometry_timer_->begin(gpu_frame_);
  }
  for (size_t m = 0; m < models_.size(); ++m)
    for (size_t l = 0; l < drawnLevels(crowd, m); ++l) {
      const ListRange r = geometryRange(crowd, m, l, false);
      stats.draw.draw_calls += renderer_
                                   .drawSkinnedIndirect(camera, *models_[m].gpu, crowd.listBuffer(), r.offset,
                                                        r.bytes, crowd.commandBuffer(), r.command * command, light, l)
                                   .draw_calls;
    }
  if (timed) gpu_geometry_timer_->end();
  for (size_t m = 0; m < models_.size(); ++m)
    stats.draw.draw_calls +=
        renderer_.drawImpostorsIndirect(camera, *models_[m].impostor->atlas, crowd.listBuffer(),
                                        crowd.listOffset(2 * m + 1), crowd.listBytes(), crowd.commandBuffer(),
                                        (2 * m + 1) * command, light, options_.blend_views)
            .draw_calls;
  stats.geometry_ms = last_geometry_ms_;
  return stats;
}

double CrowdRuntime::collectGpuGeometryMs(gpu::GpuCrowd& crowd) {
  // A frame's time and its skinned triangles arrive separately, each when the GPU is done with it: matched by frame.
  if (gpu_geometry_timer_)
    gpu_geometry_timer_->finished([&](uint64_t frame, double ms) { gpu_ms_[frame] = ms; });
  crowd.finishedCommands([&](uint64_t frame, std::span<const gpu::GpuCrowdCommand> commands) {
    uint64_t triangles = 0;
    for (size_t m = 0; m < models_.size(); ++m)
      for (size_t l = 0; l < crowd.levelCount(m); ++l)
        triangles += uint64_t(commands[crowd.levelCommand(m, l)].instance_count) * models_[m].gpu->triangleCount(l);
    gpu_triangles_[frame] = triangles;
  });
  for (auto it = gpu_ms_.begin(); it != gpu_ms_.end();) {
    const auto t = gpu_triangles_.find(it->first);
    if (t == gpu_triangles_.end()) {
      // Its triangles were never captured (every copy in flight) or are still on the way: kept a few frames.
      it = it->first + 16 < gpu_frame_ ? gpu_ms_.erase(it) : std::next(it);
      continue;
    }
    last_geometry_ms_ = it->second;
    triangle_rate_.observe(it->second, t->second);
    gpu_triangles_.erase(t);
    it = gpu_ms_.erase(it);
  }
  while (!gpu_triangles_.empty() && gpu_triangles_.begin()->first + 16 < gpu_frame_)
    gpu_triangles_.erase(gpu_triangles_.begin());
  return last_geometry_ms_;
}

CrowdFrameStats CrowdRuntime::drawGpu(const Camera& camera, gpu::GpuCrowd& crowd, CrowdPolicy policy,
                                      const gpu::LightSettings& light, const gpu::RenderTarget* occluders) {
  const std::vector<float> switches = prepareGpuCrowd(crowd, camera, policy);
  if (occluders) {
    crowd.occludeBehind(*occluders);
    occluders->bindForOpaquePass();  // the pyramid's compute left the draw state to us
  }
  crowd.cullAndClassify(camera, switches);
  return drawGpuLists(camera, crowd, light);
}

CrowdFrameStats CrowdRuntime::drawGpuShadowed(const Camera& camera, gpu::GpuCrowd& crowd, CrowdPolicy policy,
                                              const gpu::LightSettings& light, const gpu::RenderTarget& target,
                                              const CrowdShadowOptions& shadows, bool occlude) {
  const std::vector<float> switches = prepareGpuCrowd(crowd, camera, policy);
  if (occlude) crowd.occludeBehind(target);
  crowd.cullAndClassify(camera, switches);
  // The map over the receivers, grown by what a caster standing on one reaches (its sphere about its feet).
  float reach = 0.0f;
  for (const Model& m : models_) reach = std::max(reach, glm::length(m.centre) + 2.0f * m.radius);
  const ShadowFit fit = fitShadowReceivers(camera, light.direction, shadows.distance_m, shadows.map_size, reach);
  if (!shadow_map_ || shadow_map_->size() != shadows.map_size)
    shadow_map_ = std::make_unique<gpu::ShadowMap>(shadows.map_size);
  const Vec3 to_light = -glm::normalize(light.direction);
  crowd.castShadows(camera, switches, fit.projection.view_proj, fit.projection.texel_m * float(shadows.map_size),
                    fit.projection.depth_range_m, to_light);
  shadow_map_->bindForCasters();
  const size_t command = sizeof(gpu::GpuCrowdCommand);
  for (size_t m = 0; m < models_.size(); ++m) {
    const size_t i = crowd.casterList(m, true);
    for (size_t l = 0; l < drawnLevels(crowd, m); ++l) {
      const ListRange r = geometryRange(crowd, m, l, true);
      renderer_.drawSkinnedDepthIndirect(fit.projection.view_proj, *models_[m].gpu, crowd.listBuffer(), r.offset,
                                         r.bytes, crowd.commandBuffer(), r.command * command, l);
    }
    renderer_.drawImpostorDepthIndirect(fit.projection.view_proj, to_light, *models_[m].impostor->atlas,
                                        crowd.listBuffer(), crowd.listOffset(i), crowd.listBytes(),
                                        crowd.commandBuffer(), i * command);
  }
  target.bindForOpaquePass();
  CrowdFrameStats stats = drawGpuLists(camera, crowd, light);
  stats.shadow_texel_m = fit.projection.texel_m;
  if (!receiver_) receiver_ = std::make_unique<gpu::ShadowReceiver>();
  receiver_->apply(camera, *shadow_map_, fit.projection, target, light, shadows.agent_id_mask, shadows.bias_m,
                   shadows.distance_m, fit.screen_rects);
  target.bindForOpaquePass();
  return stats;
}

}  // namespace farfield::runtime
