// Crowd runtime: per frame, each agent in view is drawn as skinned instanced geometry or as a multi-view impostor
// (Tecchia, Loscos and Chrysanthou; Steed's lecture part 3), chosen by the impostor's promises: geometry where a
// texel of the atlas would cover more than a pixel (Dobbyn et al.'s switch) or where the view quantisation error
// would exceed the error bound; the nearest view and animation frame per agent otherwise.
#pragma once

#include <memory>
#include <span>
#include <string>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/gpu/crowd_renderer.h"
#include "farfield/impostor/multi_view.h"
#include "farfield/scene/skin.h"

namespace farfield::runtime {

// What the caller (a crowd simulation, eval's generated crowd) gives per agent and frame.
struct CrowdAgentState {
  uint32_t model = 0;
  Vec3 position{0.0f};  // feet
  float heading = 0.0f;  // radians about +z, facing
  float phase = 0.0f;    // animation phase in [0, 1)
  Vec4 tint{1.0f};
  uint32_t object_id = 0;  // for the id buffer
};

struct CrowdModelOptions {
  float height_m = 1.75f;      // the model is scaled to this height (animated bounds)
  float facing_deg = 90.0f;    // turn about +z that brings the model's front to +x (glTF fronts +Z: 90 after Z up)
  std::string animation = "walk";  // name looked up by SkinnedModel::findAnimation
};

enum class CrowdPolicy { Geometry, Impostor, Mixed };

struct CrowdRuntimeOptions {
  int palette_poses = 64;  // skinned poses per animation cycle (geometry)
  int frames = 16;         // impostor frames per cycle (divides palette_poses)
  impostor::ViewGrid grid;  // 32 x 8 as in the lecture
  float texel_m = 0.03f;   // atlas texel size, metres
  double error_px = 2.0;   // bound on the view quantisation error (pixels) for Mixed
};

// Agents drawn in a frame, by representation.
struct CrowdFrameStats {
  size_t in_view = 0;
  size_t geometry = 0;
  size_t impostors = 0;
  gpu::FrameStats draw;
};

class CrowdRuntime {
 public:
  // Uploads each model with its pose palette and bakes its atlas (needs a current context). Throws
  // farfield::Error for a model without animations or options out of range.
  CrowdRuntime(std::span<const scene::SkinnedModel> models, std::span<const CrowdModelOptions> model_options,
               const CrowdRuntimeOptions& options);
  ~CrowdRuntime();

  // Draws the agents into the bound target (no clear, no wait) with the camera's frustum culling (bounding
  // spheres) and the policy: Geometry = all skinned, Impostor = all impostors, Mixed = the switch above.
  CrowdFrameStats draw(const Camera& camera, std::span<const CrowdAgentState> agents, CrowdPolicy policy,
                       const gpu::LightSettings& light);

  // Waits for the GPU (frame timings).
  void finish() const { renderer_.finish(); }
  // The switch distance of model m for a camera (metres; Dobbyn's texel rule and the view error bound).
  impostor::SwitchDistances switchDistances(size_t m, const Camera& camera) const;
  size_t modelCount() const { return models_.size(); }
  const impostor::MultiViewImpostor& impostor(size_t m) const { return *models_[m].impostor; }
  double bakeSeconds() const;
  size_t atlasBytes() const;
  float cycleSeconds(size_t m) const { return models_[m].cycle_s; }
  uint64_t modelTriangles(size_t m) const { return models_[m].gpu->triangleCount(); }

 private:
  struct Model {
    std::unique_ptr<gpu::SkinnedGpuModel> gpu;
    std::unique_ptr<impostor::MultiViewImpostor> impostor;
    Vec3 centre{0.0f};  // agent space
    float radius = 1.0f;
    float cycle_s = 1.0f;
  };
  CrowdRuntimeOptions options_;
  gpu::CrowdRenderer renderer_;
  std::vector<Model> models_;
  std::vector<std::vector<gpu::CrowdAgentGpu>> geometry_, impostors_;  // per model, reused per frame
};

}  // namespace farfield::runtime
