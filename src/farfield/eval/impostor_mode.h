// Walkthrough with cell impostors (Sillion et al. 1997, sections 3 and 5): per frame, the viewer's cell (oriented
// street edge) is looked up from the camera position and heading, its local model is drawn as geometry (culled to the
// view frustum) and its distant model as the cell's impostor. Bench/walk modes "depth-mesh" and "grid-mesh".
//
// Sillion's cell impostor is the pipeline's single stage (`farfield bake --technique depth-mesh|grid-mesh` bakes
// `--pipeline near-far,single --layer-mesh depth-mesh|grid --station-spacing 0`), so these modes are thin adapters
// over runtime::Walkthrough with Representation::Smi (runtime/walkthrough.h), like the modes of mmi_mode.h, under
// the names users and scripts know. They keep the error bound: the impostor is drawn only where its validity region
// (computed at bake time) holds the eye under the bound, the far objects as geometry elsewhere; info() reports the
// bound and how often it had to draw geometry to keep it. A cell that was not baked falls back to frustum-culled
// geometry for everything (counted).
//
// Mode options (--mode-option key=value, or `farfield bench --impostors DIR`):
//   impostor_dir=DIR      impostor store of the single stage (bake --technique, or a pipeline with single); its
//                         single mesh must be the mode's kind (layer_mesh depth-mesh for depth-mesh, grid for
//                         grid-mesh): a store holds one kind
//   depth_mesh_dir=DIR    store for the depth-mesh mode only (overrides impostor_dir), likewise grid_mesh_dir=DIR:
//                         for the two stores of `bake --technique depth-mesh -o A` and `--technique grid-mesh -o B`
//   error_px=PX, gpu_budget_mb=MB, memory_budget_mb=MB, streaming_csv=FILE, geometry=gpu|cpu, occlusion=on|off,
//   occluder_share=S (as
//   mmi_mode.h), read_ahead=on|off, impostor_ids=object|layer, cell_lookup=street|nearest
//                         as for the smi mode (eval/mmi_mode.h)
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>

#include "farfield/eval/mode.h"
#include "farfield/eval/plan_geometry.h"
#include "farfield/runtime/walkthrough.h"

namespace farfield::eval {

// Registers "depth-mesh" and "grid-mesh", and the pipeline-store modes of mmi_mode.h (local, visible, smi, mmi,
// mmi-dynamic), into eval's mode registry (idempotent). Executables call it before they
// list or create modes (see the .cpp for why registration is not a static object).
void registerImpostorModes();

class ImpostorMode final : public Mode {
 public:
  // technique: "depth-mesh" or "grid-mesh" (the mode's name). Throws farfield::Error for a missing store option or a
  // bad mode option.
  ImpostorMode(std::string technique, const ModeContext& context);
  ~ImpostorMode() override;

  std::string name() const override { return technique_; }
  // Opens the store: throws farfield::Error naming it for a store of Sillion records (written before the bake became
  // the single stage: re-bake), one without the single stage, or one whose single mesh is of the other kind.
  void prepare(const ModeContext& context) override;
  void frame(FrameContext& frame) override;
  std::optional<gpu::FrameStats> lateFrameStats(size_t path_frame) override {
    return geometry_->lateFrameStats(path_frame);
  }
  void frameMeasured(size_t path_frame, double wall_ms) override { geometry_->frameMeasured(path_frame, wall_ms); }
  GpuCullRun* gpuCullRun() override { return geometry_ ? geometry_->gpuRun() : nullptr; }
  bool setGeometryErrorPx(double px) override { return geometry_ && geometry_->setGeometryErrorPx(px); }
  // The walkthrough's statistics (runtime::Walkthrough::statistics): cells, loads, fallback frames, triangles, and
  // the bound with the layer draws it turned into geometry.
  std::map<std::string, double> info() const override;

 private:
  std::string technique_;
  runtime::WalkthroughOptions options_;
  std::unique_ptr<runtime::Walkthrough> walkthrough_;
  std::optional<PlanGeometry> geometry_;  // how the plans' geometry is drawn (--mode-option geometry, occlusion)
};

}  // namespace farfield::eval
