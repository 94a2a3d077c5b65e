// Occlusion culling inside a bench frame: gpu::OcclusionCuller drawing its occluders as a pass of the frame and
// leaving the rest of the items that are not hidden to the frame's main pass. Exact: the frame is the one the items
// draw without it. Used by the culled mode and by the walkthrough adapters for their plans' geometry.
#pragma once

#include <map>
#include <span>
#include <string>

#include "farfield/eval/mode.h"
#include "farfield/gpu/occlusion_culler.h"
#include "farfield/runtime/walkthrough.h"

namespace farfield::eval {

class OcclusionPass {
 public:
  explicit OcclusionPass(double occluder_share = 0.1);

  // Draws the nearest of items now as a pass of frame and appends the others that are not hidden to frame.items().
  // bounds: parallel to items, each in its mesh's own space (GpuScene::appendDrawItems).
  void run(FrameContext& frame, std::span<const gpu::DrawItem> items, std::span<const Box3> bounds);
  // Per-frame means over the frames run: occlusion_hidden_items_per_frame, occlusion_hidden_triangles_per_frame,
  // occlusion_occluder_items_per_frame, occlusion_readback_ms_per_frame, occlusion_test_ms_per_frame; empty before.
  std::map<std::string, double> info() const;

 private:
  gpu::OcclusionCuller culler_;
  uint64_t frames_ = 0, hidden_ = 0, occluders_ = 0;
  double hidden_triangles_ = 0.0, readback_ms_ = 0.0, test_ms_ = 0.0;
};

// The occluder share of --mode-option occluder_share (a number in [0, 1], default 0.1).
double occluderShareOption(const ModeContext& context, const std::string& mode_name);

// Submits a walkthrough's plan to the frame: its geometry through `occlusion` when given (else as it is), then its
// impostors.
void submitPlan(FrameContext& frame, const runtime::FramePlan& plan, OcclusionPass* occlusion);

}  // namespace farfield::eval
