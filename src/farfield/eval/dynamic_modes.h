// Bench modes of the lecture's impostor kinds (steed-ibr-impostors-lecture, part 2): "billboard" (the scene's trees
// as cylindrical or spherical billboards where they keep the bound, geometry elsewhere), "dynamic-shade" and
// "dynamic-schaufler" (the hierarchical image cache, runtime/image_cache.h, judged by each metric). Thin adapters
// over impostor/billboard.h and runtime/image_cache.h; their numbers go to bench.json "modes.<name>.info".
//
// Mode options (--mode-option key=value, shared by the run's modes):
//   error_px=P        the bound in pixels of the frame (default 2)
//   t_max_ms=T        frame budget for regenerations (dynamic-*, default 0 = none)
//   lost_frame_investment=S (dynamic-*, layered) a frame predicted over t_max even with every invalid node as geometry
//                     still regenerates the images that pay for themselves over their previous image's reuse, up to
//                     S x t_max more
//                     (default 1; 0: such a frame draws every invalid node as geometry)
//   pay_back=on|off   (dynamic-*, layered) regenerate only images that pay for themselves over the frames they are
//                     expected to serve (the eye's speed against how far the node's images stay valid; default on);
//                     off: every invalid image that fits t_max is regenerated
//   max_regenerations=N (dynamic-*, default 32), audit=N (dynamic-*: N mesh vertices per node measure the error
//                     the metric is checked against, default 0 = off; costs frame time)
//   plane=best|front  (dynamic-*) the best plane, or the best plane moved in front of the node's samples
//   profile=FILE      (dynamic-*, layered) a cost profile of this machine (farfield calibrate over the path's view
//                     space): its model, safety factor and layered terms predict the frame; default: a quick fit here
//   geometry=gpu|cpu  (billboard, dynamic-*, layered) the geometry (what is not an image) culled and drawn by the
//                     GPU-driven frame (gpu::GpuCuller: frustum, cones, hierarchical-Z; no readback), the default, or
//                     culled on the CPU (eval/plan_geometry.h)
//   occlusion=on|off  on the GPU: the GPU culler's occlusion test; on the CPU (dynamic-*, layered): the cache's near
//                     geometry occlusion-culled against the depth of its nearest items, read back, and nodes hidden
//                     behind that depth skipped: no image, no regeneration (default on); billboard: its geometry
//                     occlusion-culled as the culled-cpu mode's
//   occluder_share=S  the nearest near items drawn first as occluders hold this share of the triangles of the near
//                     geometry and the cut's nodes (default 0.1)
//   warp_interval=N   (warp) a keyframe of culled geometry every N path frames (default 4)
//   billboard_kind=cylindrical|spherical, billboard_views=N (default 8), billboard_texels=N (default 32)
#pragma once

#include <array>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "farfield/eval/mode.h"
#include "farfield/impostor/billboard.h"
#include "farfield/impostor/dynamic.h"
#include "farfield/impostor/warp.h"
#include "farfield/eval/occlusion_pass.h"
#include "farfield/eval/plan_geometry.h"
#include "farfield/runtime/image_cache.h"

namespace farfield::eval {

// Registers billboard, dynamic-shade, dynamic-schaufler, layered and warp (called by registerImpostorModes()).
void registerDynamicModes();

class BillboardMode final : public Mode {
 public:
  explicit BillboardMode(const ModeContext& context);
  std::string name() const override { return "billboard"; }
  void prepare(const ModeContext& context) override;
  void frame(FrameContext& frame) override;
  std::optional<gpu::FrameStats> lateFrameStats(size_t path_frame) override {
    return geometry_draw_->lateFrameStats(path_frame);
  }
  void frameMeasured(size_t path_frame, double wall_ms) override { geometry_draw_->frameMeasured(path_frame, wall_ms); }
  GpuCullRun* gpuCullRun() override { return geometry_draw_ ? geometry_draw_->gpuRun() : nullptr; }
  std::map<std::string, double> info() const override;

 private:
  impostor::BillboardOptions options_;
  double error_px_ = 2.0;
  const gpu::GpuScene* gpu_scene_ = nullptr;
  const scene::Bvh* bvh_ = nullptr;
  std::vector<uint32_t> tree_of_object_;  // per object id: billboard index + 1, 0 = not a tree
  std::vector<uint32_t> tree_ids_;
  std::unique_ptr<impostor::BillboardBatch> batch_;
  std::vector<uint32_t> visible_, geometry_, boards_;
  std::optional<PlanGeometry> geometry_draw_;  // the geometry on the GPU or the CPU (--mode-option geometry, occlusion)
  double prepare_s_ = 0.0;
  size_t frames_ = 0, billboards_drawn_ = 0, trees_as_geometry_ = 0, uploaded_bytes_ = 0;
};

class DynamicImpostorMode final : public Mode {
 public:
  DynamicImpostorMode(impostor::ValidityMetric metric, const ModeContext& context,
                      runtime::CachedImageKind kind = runtime::CachedImageKind::Planar);
  std::string name() const override;
  void prepare(const ModeContext& context) override;
  void frame(FrameContext& frame) override;
  std::optional<gpu::FrameStats> lateFrameStats(size_t path_frame) override {
    return geometry_draw_ ? geometry_draw_->lateFrameStats(path_frame) : std::nullopt;
  }
  void frameMeasured(size_t path_frame, double wall_ms) override {
    if (geometry_draw_) geometry_draw_->frameMeasured(path_frame, wall_ms);
  }
  GpuCullRun* gpuCullRun() override { return geometry_draw_ ? geometry_draw_->gpuRun() : nullptr; }
  std::map<std::string, double> info() const override;

 private:
  // geometry=gpu: the cache's geometry as objects, culled and drawn by the GPU (no CPU occlusion, no readback).
  std::optional<PlanGeometry> geometry_draw_;
  std::vector<uint32_t> geometry_objects_;
  runtime::ImageCacheOptions options_;
  std::unique_ptr<runtime::ImageCache> cache_;
  const scene::Scene* scene_ = nullptr;
  const gpu::GpuScene* gpu_scene_ = nullptr;
  size_t last_frame_ = size_t(-1);
  // Sums over measured frames (a repeated frame counts once: its last run).
  std::map<size_t, runtime::ImageCacheFrameStats> per_frame_;
  double calibrate_s_ = 0.0;
  std::string profile_path_;  // --mode-option profile=FILE: the cost profile to predict with ("" = calibrate here)
  std::optional<runtime::ImageCacheOcclusion> occlusion_;  // --mode-option occlusion=on (target set per frame)
};

// Post-render warping (the lecture's "Post-render warping (Mark et al.)" and "3D warping using depth"): every
// warp_interval path frames a keyframe of culled geometry is rendered and read back (colour and depth); the frames
// between warp the latest keyframe to their camera, filling its holes from the one before (impostor/warp.h), and
// draw the result as one screen quad (an upload per frame).
class WarpMode final : public Mode {
 public:
  explicit WarpMode(const ModeContext& context);
  std::string name() const override { return "warp"; }
  void prepare(const ModeContext& context) override;
  void frame(FrameContext& frame) override;
  std::map<std::string, double> info() const override;

 private:
  struct Keyframe {
    image::ColorImage color;
    image::DepthImage depth;
    Camera camera;
    size_t path_frame = 0;
  };
  void drawScreenQuad(FrameContext& frame, const image::ColorImage& image);
  size_t interval_ = 4;
  const gpu::GpuScene* gpu_scene_ = nullptr;
  const scene::Bvh* bvh_ = nullptr;
  std::vector<Keyframe> keys_;  // at most two, oldest first
  std::vector<uint32_t> ids_;
  std::unique_ptr<gpu::Texture> texture_;
  std::unique_ptr<gpu::GpuMaterial> material_;
  gpu::GpuMesh quad_;
  std::map<size_t, std::array<double, 4>> per_frame_;  // keyframe?, bytes read back, bytes uploaded, holes
};

}  // namespace farfield::eval
