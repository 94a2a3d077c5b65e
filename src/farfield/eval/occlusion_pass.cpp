#include "farfield/eval/occlusion_pass.h"

#include <cstdlib>

#include "farfield/core/error.h"

namespace farfield::eval {

OcclusionPass::OcclusionPass(double occluder_share) : culler_(occluder_share) {}

void OcclusionPass::run(FrameContext& frame, std::span<const gpu::DrawItem> items, std::span<const Box3> bounds) {
  const gpu::OcclusionStats stats = culler_.cull(
      frame.camera(), items, bounds, frame.beginOwnPass(),
      [&](std::span<const gpu::DrawItem> occluders) { frame.drawPass(occluders); }, frame.items());
  ++frames_;
  hidden_ += stats.hidden;
  hidden_triangles_ += double(stats.hidden_triangles);
  occluders_ += stats.occluders;
  readback_ms_ += stats.readback_ms;
  test_ms_ += stats.pyramid_ms;
}

std::map<std::string, double> OcclusionPass::info() const {
  if (frames_ == 0) return {};
  const double n = double(frames_);
  return {{"occlusion_hidden_items_per_frame", double(hidden_) / n},
          {"occlusion_hidden_triangles_per_frame", hidden_triangles_ / n},
          {"occlusion_occluder_items_per_frame", double(occluders_) / n},
          {"occlusion_readback_ms_per_frame", readback_ms_ / n},
          {"occlusion_test_ms_per_frame", test_ms_ / n}};
}

double occluderShareOption(const ModeContext& context, const std::string& mode_name) {
  const std::string text = context.option("occluder_share", "0.1");
  char* end = nullptr;
  const double share = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0' || !(share >= 0.0 && share <= 1.0))
    throw Error("mode '" + mode_name + "'", "occluder_share must be a number in [0, 1], got '" + text + "'");
  return share;
}

void submitPlan(FrameContext& frame, const runtime::FramePlan& plan, OcclusionPass* occlusion) {
  const auto geometry_end = plan.items.begin() + std::ptrdiff_t(plan.geometry_items);
  if (occlusion && plan.geometry_items > 0) {
    occlusion->run(frame, std::span<const gpu::DrawItem>(plan.items.data(), plan.geometry_items),
                   plan.geometry_bounds);
  } else {
    frame.items().insert(frame.items().end(), plan.items.begin(), geometry_end);
  }
  frame.items().insert(frame.items().end(), geometry_end, plan.items.end());
}

}  // namespace farfield::eval
