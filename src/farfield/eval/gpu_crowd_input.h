// A generated crowd (gen/crowd.h) as the GPU crowd's plain data (gpu/gpu_crowd.h; issue 45): its sidewalk loops with
// the ground's height at each point, and its agents.
#pragma once

#include <vector>

#include "farfield/gen/crowd.h"
#include "farfield/gpu/gpu_crowd.h"

namespace farfield::eval {

std::vector<gpu::GpuCrowdRoute> gpuCrowdRoutes(const gen::Crowd& crowd);
// Agent i's object id is id_bits | i (eval's crowdAgentStates: kCrowdIdBit | i).
std::vector<gpu::GpuCrowdAgent> gpuCrowdAgents(const gen::Crowd& crowd, uint32_t id_bits = 0);

}  // namespace farfield::eval
