// A crowd walking a city's sidewalks, as the crowd bench and the viewer draw it: the skinned models (the built-in
// figures, or glTF files) with their heights, facings and shares, the agents' states (position, heading, walk phase) at a time from gen's routes, and one
// frame of the crowd drawn into a target holding the city, with or without the agents' shadows.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/gen/crowd.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/renderer.h"
#include "farfield/runtime/crowd_runtime.h"
#include "farfield/scene/skin.h"

namespace farfield::eval {

// The defaults for glTF files given as the crowd's models (--models, --crowd-models), by model index: those of the
// shared models (../shared/data/models CesiumMan.glb, Fox.glb): heights in metres, the turn bringing each front to
// +x (CesiumMan walks along +x once Z up; the Fox faces glTF's +z, -y), shares of agents.
// m/s at which a model's walk cycle is played at its own rate (crowdAgentStates' phase; the GPU crowd's stride).
inline constexpr float kCrowdNominalSpeed = 1.3f;
inline const std::vector<float> kCrowdModelHeights{1.75f, 0.8f};
inline const std::vector<float> kCrowdModelFacingDeg{0.0f, 90.0f};
inline const std::vector<float> kCrowdModelShares{0.7f, 0.3f};

// The built-in figures' (gen/walker_figure.h, gen/quadruped_figure.h: the crowd's models when no files are given),
// by model index: their heights as made (metres, so that a walk cycle covers their stride at the nominal speed), no
// turn (both are made facing +x), shares of agents.
inline const std::vector<float> kBuiltinCrowdModelHeights{1.77f, 0.7f};
inline const std::vector<float> kBuiltinCrowdModelFacingDeg{0.0f, 0.0f};
inline const std::vector<float> kBuiltinCrowdModelShares{0.7f, 0.3f};

// The skinned models of a crowd, the runtime's options for each (height in metres, facing in degrees) and each
// one's share of the agents.
struct CrowdModels {
  std::vector<scene::SkinnedModel> models;
  std::vector<runtime::CrowdModelOptions> options;
  std::vector<std::string> names;  // the files' names ("builtin:walker" for a built-in figure), for reports
  std::vector<float> shares;
};

// The built-in figures, a walker and a four-legged one (gen::makeWalkerFigure, gen::makeQuadrupedFigure), with
// kBuiltinCrowdModel* heights, facings and shares: a crowd that reads no file.
CrowdModels builtinCrowdModels();

// Loads each file (scene::importSkinnedModel; its import warnings logged). Throws farfield::Error naming the file,
// or for no files or fewer heights, facings or shares than files.
CrowdModels loadCrowdModels(std::span<const std::string> files, std::span<const float> heights,
                            std::span<const float> facing_deg, std::span<const float> shares);

// The crowd's models: without files the built-in figures (builtinCrowdModels; heights, facings and shares are then
// theirs, the arguments unused), else loadCrowdModels.
CrowdModels crowdModels(std::span<const std::string> files, std::span<const float> heights,
                        std::span<const float> facing_deg, std::span<const float> shares);

// Every agent's state at time t (seconds): where gen's route puts it, its heading, and its walk phase advanced by the
// distance walked over its model's stride at the nominal speed (the cycle played at its own rate at 1.3 m/s). Object
// ids are kCrowdIdBit | agent index.
std::vector<runtime::CrowdAgentState> crowdAgentStates(const gen::Crowd& crowd, const runtime::CrowdRuntime& rt,
                                                       float t);

// The crowd into `target` (holding the city): with shadows through rt.drawShadowed (the casters' shadows on the
// city), else rt.draw into the target's opaque pass.
runtime::CrowdFrameStats drawCrowdFrame(runtime::CrowdRuntime& rt, const Camera& camera,
                                        std::span<const runtime::CrowdAgentState> states, runtime::CrowdPolicy policy,
                                        const gpu::LightSettings& light, const gpu::RenderTarget& target, bool shadows,
                                        const runtime::CrowdShadowOptions& shadow);

}  // namespace farfield::eval
