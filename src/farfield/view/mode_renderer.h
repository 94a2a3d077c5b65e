// The viewer's frames: one mode at a time, switchable while running, drawn into one render target with the shared
// renderer. full and culled are eval's built-in modes run through eval::FrameRunner; the database's representations
// (local, visible, smi, mmi, mmi-dynamic, placed) go through the runtime's product API, runtime::Walkthrough, whose
// plan (items, per-layer decisions, report) the panels show, its geometry drawn by the GPU-driven frame (the plan's
// objects through the run's arena: gpu::GpuCuller) and its impostors by the renderer, timed by the same FrameRunner.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/eval/frame_runner.h"
#include "farfield/eval/gpu_culled_mode.h"
#include "farfield/eval/mode.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/renderer.h"
#include "farfield/runtime/walkthrough.h"
#include "farfield/scene/bvh.h"
#include "farfield/scene/scene.h"
#include "farfield/view/impostor_kinds.h"

namespace farfield::view {

struct ModeSettings {
  std::string database;        // impostor database directory ("" = none)
  double error_px = 0.0;       // the walkthrough's bound; 0 = the database's
  uint64_t gpu_budget_bytes = uint64_t(512) << 20;
  // A terrain under the city (eval/city_on_terrain_mode.h), drawn by terrain_technique in full and culled: a DEM file
  // or fractal:... spec and the vertical scale the city was made with (gen city --terrain SPEC --terrain-scale S).
  std::string terrain;
  float terrain_scale = 1.0f;
  // The terrain technique (eval/city_on_terrain_mode.h): lod-sprite-gpu, high-gpu, lod-sprite or high.
  std::string terrain_technique = "lod-sprite-gpu";
  // The frame budget the governed mode keeps (its governor_t_max_ms), as it is when the mode is selected.
  double t_max_ms = 1000.0 / 30.0;
  // Walkthrough modes: time each frame spends after its draws loading what the next frames will need (the cells or
  // placed impostors ahead: runtime::Walkthrough::loadAhead), so that entering a cell uploads nothing; 0: none.
  double load_ahead_ms = 2.0;
};

// One displayed frame.
struct ViewFrame {
  double cpu_ms = 0.0;   // from the mode's selection (plan) through the draw to glFinish
  double gpu_ms = 0.0;   // gpu::GpuTimer (the renderer's)
  uint64_t triangles = 0;
  uint32_t draw_calls = 0;
  const runtime::FramePlan* plan = nullptr;  // walkthrough modes; valid until the next frame
  std::array<size_t, kDecisionKinds> decisions{};
  // The governed mode: the governor's decision for this frame, and the bound it kept (the promised bound x its
  // bound scale, in pixels); 0 in the other modes.
  std::optional<eval::FrameGovernance> governance;
  double kept_bound_px = 0.0;
};

class ModeRenderer {
 public:
  // Everything given must outlive the renderer; needs the OpenGL context current.
  ModeRenderer(const scene::Scene& scene, const gpu::GpuScene& gpu_scene, const scene::Bvh& bvh,
               gpu::Renderer& renderer, gpu::RenderTarget& target, ModeSettings settings);
  ~ModeRenderer();

  // Switches to a mode ("full", "culled", a runtime representation name, or "governed": the placed walkthrough of a
  // placement database under eval's frame governor, keeping settings' t_max_ms). Throws farfield::Error (an unknown
  // name, a database that cannot draw it, a damaged database, a city that does not lie on the terrain, governed
  // without a placement or a budget); the previous mode stays in use then. With a terrain, full and culled draw it
  // under the city; the representations do not (a warning says so).
  void select(const std::string& mode);
  const std::string& mode() const { return mode_; }
  // A new frame budget for the governed mode: made again (and calibrated again) when it is the mode in use.
  void setTMaxMs(double t_max_ms);
  // The walkthrough of the current mode, null for full and culled.
  const runtime::Walkthrough* walkthrough() const { return walkthrough_.get(); }

  // Renders the camera's frame into the target and waits for it. tint: impostor items tinted by kind.
  ViewFrame render(const Camera& camera, size_t frame_index, bool tint);
  // Draws the last frame's items again (walkthrough modes: without planning again; full and culled: the same
  // camera run again), tinted or not: the reference check measures the untinted frame.
  void redraw(const Camera& camera, size_t frame_index, bool tint);

 private:
  const scene::Scene& scene_;
  const gpu::GpuScene& gpu_scene_;
  const scene::Bvh& bvh_;
  gpu::Renderer& renderer_;
  gpu::RenderTarget& target_;
  ModeSettings settings_;
  eval::ModeContext context_;
  eval::FrameRunner runner_;
  std::string mode_;
  std::unique_ptr<eval::Mode> eval_mode_;
  std::unique_ptr<runtime::Walkthrough> walkthrough_;
  // A walkthrough's frame as a mode of the runner: plans (or not, for a redraw), then the plan's geometry objects on
  // the GPU and its items (tinted or not) in the main pass.
  class PlanFrame;
  friend class PlanFrame;
  std::unique_ptr<PlanFrame> plan_frame_;
  std::unique_ptr<eval::Mode> governedMode();
  double governed_bound_px_ = 0.0;  // the governed mode's promised bound
  std::optional<eval::GpuCullRun> geometry_;  // the walkthrough modes' GPU-driven geometry
  uint64_t geometry_version_ = ~uint64_t(0);

  const runtime::FramePlan* last_plan_ = nullptr;
  std::vector<gpu::DrawItem> last_items_;  // the walkthrough's last plan, untinted (its impostors)
  std::vector<size_t> last_kinds_;         // and the kinds of its items
  std::vector<gpu::GpuMaterial> tint_materials_;
  std::vector<gpu::DrawItem> tinted_;
};

}  // namespace farfield::view
