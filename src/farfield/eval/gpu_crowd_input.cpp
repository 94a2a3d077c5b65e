#include "farfield/eval/gpu_crowd_input.h"

namespace farfield::eval {

std::vector<gpu::GpuCrowdRoute> gpuCrowdRoutes(const gen::Crowd& crowd) {
  std::vector<gpu::GpuCrowdRoute> routes;
  routes.reserve(crowd.routes.size());
  for (const gen::SidewalkRoute& r : crowd.routes) {
    gpu::GpuCrowdRoute g;
    g.loop = r.loop;
    g.distance = r.distance;
    g.length = r.length;
    if (crowd.ground_height)
      for (const Vec2& p : r.loop) g.ground.push_back(crowd.ground_height(p.x, p.y));
    routes.push_back(std::move(g));
  }
  return routes;
}

std::vector<gpu::GpuCrowdAgent> gpuCrowdAgents(const gen::Crowd& crowd, uint32_t id_bits) {
  std::vector<gpu::GpuCrowdAgent> agents;
  agents.reserve(crowd.agents.size());
  for (size_t i = 0; i < crowd.agents.size(); ++i) {
    const gen::CrowdAgent& a = crowd.agents[i];
    agents.push_back(
        {a.route, a.model, a.outfit, id_bits | uint32_t(i), a.start, a.speed, float(a.direction), a.phase, a.tint});
  }
  return agents;
}

}  // namespace farfield::eval
