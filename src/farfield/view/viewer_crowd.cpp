#include "farfield/view/viewer_crowd.h"

#include <cmath>
#include <utility>

#include "farfield/core/timer.h"
#include "farfield/eval/crowd_metrics.h"
#include "farfield/eval/gpu_crowd_input.h"

namespace farfield::view {

ViewerCrowd::ViewerCrowd(const urban::StreetGraph& streets, std::function<float(float, float)> ground_height,
                         const ViewerCrowdOptions& options, int height_px)
    : options_(options) {
  models_ = eval::crowdModels(options.models, eval::kCrowdModelHeights, eval::kCrowdModelFacingDeg,
                              eval::kCrowdModelShares);
  gen::CrowdOptions co;
  co.agents = options.agents;
  co.seed = options.seed;
  co.model_shares = models_.shares;
  co.ground_height = std::move(ground_height);
  crowd_ = gen::generateCrowd(streets, co);
  runtime::CrowdRuntimeOptions ro;
  ro.error_px = options.error_px;
  ro.geometry_lod_px = options.lod_px;
  ro.max_geometry_triangles = options.max_triangles;
  ro.geometry_ms = options.geometry_ms;
  ro.bound_focal_px = double(height_px) / (2.0 * std::tan(double(Camera{}.fov_y) / 2.0));
  ro.region_tints = crowd_.region_tints;
  rt_ = std::make_unique<runtime::CrowdRuntime>(models_.models, models_.options, ro);
  if (options.gpu)
    gpu_crowd_ = std::make_unique<gpu::GpuCrowd>(eval::gpuCrowdRoutes(crowd_),
                                                 eval::gpuCrowdAgents(crowd_, eval::kCrowdIdBit),
                                                 rt_->gpuCrowdModels(eval::kCrowdNominalSpeed));
}

ViewerCrowd::~ViewerCrowd() = default;

ViewerCrowdFrame ViewerCrowd::draw(const Camera& camera, float t, const gpu::LightSettings& light,
                                   const gpu::RenderTarget& target) {
  const Stopwatch clock;
  if (gpu_crowd_) {
    target.bindForOpaquePass();
    gpu_crowd_->simulate(t);
    ViewerCrowdFrame frame;
    frame.stats = options_.shadows ? rt_->drawGpuShadowed(camera, *gpu_crowd_, runtime::CrowdPolicy::Mixed, light,
                                                          target, runtime::CrowdShadowOptions{}, true)
                                   : rt_->drawGpu(camera, *gpu_crowd_, runtime::CrowdPolicy::Mixed, light, &target);
    rt_->finish();
    frame.ms = clock.milliseconds();
    return frame;
  }
  const std::vector<runtime::CrowdAgentState> states = eval::crowdAgentStates(crowd_, *rt_, t);
  runtime::CrowdShadowOptions shadow;
  shadow.impostor_casters = true;
  rt_->cullBehind(target);
  ViewerCrowdFrame frame;
  frame.stats = eval::drawCrowdFrame(*rt_, camera, states, runtime::CrowdPolicy::Mixed, light, target,
                                     options_.shadows, shadow);
  rt_->finish();
  frame.ms = clock.milliseconds();
  return frame;
}

}  // namespace farfield::view
