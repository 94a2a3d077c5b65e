// The viewer's crowd: agents walking the city's sidewalks (gen::generateCrowd on the street graph, standing on the
// scene's ground), drawn by the crowd runtime after the mode's frame as crowd-mixed draws them (skinned near,
// multi-view impostors far, their shadows on the city). The same models, runtime and per-frame states as
// `farfield crowd bench` (eval/crowd_walk.h); or, with ViewerCrowdOptions::gpu, the GPU crowd's (crowd-mixed-gpu).
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/eval/crowd_walk.h"
#include "farfield/gen/crowd.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/renderer.h"
#include "farfield/runtime/crowd_runtime.h"
#include "farfield/urban/street_graph.h"

namespace farfield::view {

struct ViewerCrowdOptions {
  size_t agents = 0;                // 0: no crowd
  // Skinned glTF files (CesiumMan 1.75 m, Fox 0.8 m: the first two heights); empty: the built-in figures, a walker
  // and a four-legged one (eval::builtinCrowdModels), no file read.
  std::vector<std::string> models;
  uint64_t seed = 2;
  double error_px = 1.0;            // the impostors' bound (crowd-mixed's switch)
  double lod_px = 0.0;              // skinned levels of detail within this many pixels (0: the mesh; seconds to build)
  uint64_t max_triangles = 20000;   // skinned triangles a frame (0: no budget)
  double geometry_ms = 0.0;         // skinned drawing a frame in ms, at the measured time per triangle (0: none)
  bool shadows = true;
  // The crowd simulated, culled (frustum, and behind the mode's frame), classified, drawn and shadowed on the GPU
  // (gpu/gpu_crowd.h, CrowdRuntime::drawGpuShadowed): no per-agent work on the CPU; the budgets (triangles,
  // milliseconds) and the levels of detail hold there too.
  bool gpu = false;
};

// What one crowd frame drew and took.
struct ViewerCrowdFrame {
  runtime::CrowdFrameStats stats;
  double ms = 0.0;  // the crowd pass, to glFinish
};

class ViewerCrowd {
 public:
  // Loads the models (or makes the built-in figures), places the agents on the streets' sidewalks over ground_height and bakes the impostor atlases
  // for frames of height_px pixels at the camera's field of view. Needs the OpenGL context current. Throws
  // farfield::Error naming a bad model file, or a street graph without sidewalks.
  ViewerCrowd(const urban::StreetGraph& streets, std::function<float(float, float)> ground_height,
              const ViewerCrowdOptions& options, int height_px);
  ~ViewerCrowd();
  ViewerCrowd(const ViewerCrowd&) = delete;
  ViewerCrowd& operator=(const ViewerCrowd&) = delete;

  // The crowd at time t (seconds) into `target`, which holds the mode's frame (its depth hides agents behind the
  // city); waits for the GPU.
  ViewerCrowdFrame draw(const Camera& camera, float t, const gpu::LightSettings& light, const gpu::RenderTarget& target);
  size_t agentCount() const { return crowd_.agents.size(); }
  double bakeSeconds() const { return rt_->bakeSeconds(); }

 private:
  ViewerCrowdOptions options_;
  eval::CrowdModels models_;
  gen::Crowd crowd_;
  std::unique_ptr<runtime::CrowdRuntime> rt_;
  std::unique_ptr<gpu::GpuCrowd> gpu_crowd_;  // with options.gpu
};

}  // namespace farfield::view
