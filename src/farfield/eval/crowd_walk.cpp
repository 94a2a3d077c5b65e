#include "farfield/eval/crowd_walk.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "farfield/core/error.h"
#include "farfield/core/log.h"
#include "farfield/eval/crowd_metrics.h"
#include "farfield/gen/quadruped_figure.h"
#include "farfield/gen/walker_figure.h"
#include "farfield/scene/gltf_skin.h"

namespace farfield::eval {

CrowdModels builtinCrowdModels() {
  CrowdModels out;
  out.models.push_back(gen::makeWalkerFigure());
  out.models.push_back(gen::makeQuadrupedFigure());
  for (size_t m = 0; m < out.models.size(); ++m) {
    runtime::CrowdModelOptions mo;
    mo.height_m = kBuiltinCrowdModelHeights[m];
    mo.facing_deg = kBuiltinCrowdModelFacingDeg[m];
    out.options.push_back(mo);
    out.names.push_back(out.models[m].name);
    out.shares.push_back(kBuiltinCrowdModelShares[m]);
  }
  return out;
}

CrowdModels loadCrowdModels(std::span<const std::string> files, std::span<const float> heights,
                            std::span<const float> facing_deg, std::span<const float> shares) {
  if (files.empty()) throw Error("crowd", "no skinned models given");
  const size_t most = std::min({heights.size(), facing_deg.size(), shares.size()});
  if (most < files.size())
    throw Error("crowd", "one height, facing and share per model (at most " + std::to_string(most) + " models, " +
                             std::to_string(files.size()) + " given)");
  CrowdModels out;
  for (size_t m = 0; m < files.size(); ++m) {
    scene::SkinImportStats stats;
    out.models.push_back(scene::importSkinnedModel(files[m], &stats));
    for (const std::string& w : stats.warnings()) FF_WARN(files[m] << ": " << w);
    runtime::CrowdModelOptions mo;
    mo.height_m = heights[m];
    mo.facing_deg = facing_deg[m];
    out.options.push_back(mo);
    out.names.push_back(std::filesystem::path(files[m]).filename().string());
    out.shares.push_back(shares[m]);
  }
  return out;
}

CrowdModels crowdModels(std::span<const std::string> files, std::span<const float> heights,
                        std::span<const float> facing_deg, std::span<const float> shares) {
  if (files.empty()) return builtinCrowdModels();
  return loadCrowdModels(files, heights, facing_deg, shares);
}

std::vector<runtime::CrowdAgentState> crowdAgentStates(const gen::Crowd& crowd, const runtime::CrowdRuntime& rt,
                                                       float t) {
  std::vector<runtime::CrowdAgentState> states(crowd.agents.size());
  for (size_t i = 0; i < crowd.agents.size(); ++i) {
    const gen::CrowdAgent& a = crowd.agents[i];
    const gen::AgentPose p = gen::agentPose(crowd, i, t);
    runtime::CrowdAgentState& s = states[i];
    s.model = a.model;
    s.position = p.position;
    s.heading = p.heading;
    const float stride = kCrowdNominalSpeed * rt.cycleSeconds(a.model);
    const float phase = a.phase + p.walked / stride;
    s.phase = phase - std::floor(phase);
    s.tint = a.tint;
    s.outfit = a.outfit;
    s.object_id = kCrowdIdBit | uint32_t(i);
  }
  return states;
}

runtime::CrowdFrameStats drawCrowdFrame(runtime::CrowdRuntime& rt, const Camera& camera,
                                        std::span<const runtime::CrowdAgentState> states, runtime::CrowdPolicy policy,
                                        const gpu::LightSettings& light, const gpu::RenderTarget& target, bool shadows,
                                        const runtime::CrowdShadowOptions& shadow) {
  if (shadows) return rt.drawShadowed(camera, states, policy, light, target, shadow);
  target.bindForOpaquePass();
  return rt.draw(camera, states, policy, light);
}

}  // namespace farfield::eval
