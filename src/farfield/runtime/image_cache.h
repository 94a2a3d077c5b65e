// Hierarchical image cache (Shade et al. 1996, as the steed-ibr-impostors-lecture, part 2, presents it: "Impostors
// ... the same image can be reused for several frames; when the viewpoint changes, the impostor image must be
// updated"): a k-d hierarchy over the scene's objects; per frame, the highest nodes far enough from the eye are drawn
// as cached planar images (impostor/dynamic.h) while the chosen validity metric keeps them under the error bound;
// invalid images are regenerated most invalid first inside the frame budget (runtime/regeneration_scheduler.h) and
// drawn as geometry when there is no time left. Near nodes descend to geometry.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "farfield/core/bounds.h"
#include "farfield/core/camera.h"
#include "farfield/gpu/cost_model.h"
#include "farfield/gpu/cost_profile.h"
#include "farfield/gpu/occlusion_culler.h"
#include "farfield/gpu/renderer.h"
#include "farfield/core/shaft.h"
#include "farfield/impostor/dynamic.h"
#include "farfield/impostor/layered.h"
#include "farfield/scene/scene.h"

namespace farfield::runtime {

// What a node's image is: a planar image judged by a metric, or a layered impostor (impostor/layered.h; the
// lecture's "hardware assisted image warping", depth slices selected by alpha test) planned for a shaft around the
// eye it was captured from, valid while the eye stays in that shaft (no metric: the plan keeps the bound there).
enum class CachedImageKind { Planar, Layered };

struct ImageCacheOptions {
  CachedImageKind kind = CachedImageKind::Planar;
  double layered_apex_angle = degToRad(16.0);  // the shaft's opening (Layered)
  double layered_approach = 0.8;                // the shaft's minimum distance, times the capture distance (0..1)
  impostor::ValidityMetric metric = impostor::ValidityMetric::Schaufler;
  double error_px = 1.0;        // the bound, pixels of the frame (ErrorBound::angle of the viewer camera)
  double t_max_ms = 0.0;        // frame budget; <= 0: every invalid image is regenerated (up to the count)
  int max_regenerations = 32;   // per frame
  int leaf_objects = 8;         // k-d leaves hold at most this many objects
  double min_distance_radii = 2.5;  // a node is an image only with the eye farther than this many radii away
  float max_object_radius = 150.0f; // larger objects (the ground) are always geometry
  size_t byte_budget = size_t(512) << 20;  // images kept (least recently used dropped first)
  int shade_samples = 64;       // Shade's points per node: the objects' box corners, evenly thinned to this
  int audit_samples = 0;        // > 0: per drawn image, Shade's angle over this many mesh vertices too (the
                                // "measured" error the bench checks the metric against); costs frame time
  impostor::PlanarImpostorOptions impostor;
  gpu::CostModel cost;          // predicts geometry and regeneration times (all 0: no prediction)
  double cost_safety_factor = 1.0;  // >= 1: every prediction of `cost` is multiplied by it (gpu::CostProfile's)
  // Layered images: drawing (per layer, per pixel of their quads) and regenerating (per layer, per texel: render,
  // readback, crop, upload) bounds; not calibrated: a layered regeneration is estimated as renders of the geometry.
  gpu::LayeredCost layered_cost;
  double regeneration_overhead_ms = 0.3;  // per regeneration: target, clear, state
  // A frame predicted over t_max even with every invalid node as geometry still regenerates the nodes whose images
  // pay for themselves over the frames they are expected to serve (ImageCache::expectedReuse), up to this share of
  // t_max more (runtime/regeneration_scheduler.h, invest_ms); 0: such a frame draws every invalid node as geometry.
  double lost_frame_investment = 1.0;
  // A regeneration is taken only when it pays for itself over the frames the new image is expected to serve
  // (regeneration + image - geometry <= expected reuse x (geometry - image)), in every frame and not only in a lost
  // one: where images do not live long enough, the node is drawn as geometry, which is exact and cheaper. Only with
  // a cost model that prices geometry (without one no image can pay, and every image is made as before).
  bool pay_back = true;
};

struct ImageCacheFrameStats {
  size_t images_drawn = 0;         // cached images drawn (valid or regenerated this frame)
  size_t regenerations = 0;
  size_t geometry_nodes = 0;       // invalid nodes drawn as geometry (no time to regenerate)
  bool lost = false;               // predicted over t_max even with every invalid node as geometry
  size_t near_objects = 0;         // objects drawn as geometry because they are near (or large)
  double predicted_ms = 0.0;
  size_t texture_bytes = 0;        // all cached images (after this frame)
  size_t texels_written_bytes = 0; // colour written into images this frame (the update's traffic)
  size_t uploaded_bytes = 0;       // quad meshes of regenerated images
  // Audit (ImageCacheOptions::audit_samples > 0): per image the metric judged this frame, against the measured
  // error (Shade's angle over mesh vertices).
  size_t audited = 0;
  size_t unneeded = 0;  // the metric said invalid, the measured error was within the bound
  size_t missed = 0;    // the metric said valid, the measured error was over the bound
  // Occlusion culling (ImageCacheOcclusion): near items drawn first as occluders, near items hidden behind them,
  // nodes of the cut hidden behind them (no image drawn, none regenerated, no geometry), and the time spent waiting
  // for the occluders' depth and testing boxes against it.
  size_t occluders = 0;
  size_t hidden_items = 0;
  uint64_t hidden_triangles = 0;  // of the hidden near items
  size_t hidden_nodes = 0;
  uint64_t hidden_node_triangles = 0;
  // Items of the nodes drawn as geometry (their invalid images not regenerated) hidden behind the occluders: such a
  // node costs only what it shows, as in frustum- and occlusion-culled geometry.
  size_t hidden_fallback_items = 0;
  uint64_t hidden_fallback_triangles = 0;
  double occlusion_ms = 0.0;
};

// Occlusion culling inside the cache's frame (gpu/occlusion_culler.h). The nearest of the near geometry's items (until
// they hold occluder_share of the triangles of the near geometry and the cut's nodes, and every item reaching behind
// the eye) are drawn first by draw_occluders into the frame's target; the depth they leave hides the other near
// items, whole nodes of the cut whose boxes lie behind it, and the items of nodes drawn as geometry. A hidden node
// needs no image, no regeneration and no geometry this frame, and the budget is planned without it. Exact for
// geometry (nothing hidden could draw a pixel); a hidden node's image could only have drawn pixels that its own
// geometry does not show.
struct ImageCacheOcclusion {
  const gpu::RenderTarget* target = nullptr;  // the frame's target, into which draw_occluders draws
  std::function<void(std::span<const gpu::DrawItem>)> draw_occluders;
  double occluder_share = 0.1;  // in [0, 1]
};

class ImageCache {
 public:
  // Keeps references to the scene and its GPU copy. Throws farfield::Error for bad options.
  ImageCache(const scene::Scene& scene, const gpu::GpuScene& gpu_scene, const ImageCacheOptions& options);
  ~ImageCache();

  // The frame for `camera`: regenerates images with Renderer::draw (call inside a frame after the frame's own-pass
  // start), appends the main pass (geometry and images) to `out`. A call with the same frame_index as the previous
  // call repeats that frame's work (the same regenerations), so repeated timings of one frame time the same work.
  // With `occlusion`, the occluders are drawn through it before any regeneration, and `out` receives only what they
  // do not hide.
  // With `geometry_objects` (a GPU-driven frame: gpu::GpuCuller culls and draws them), the geometry goes there as
  // object ids (the near objects and those of the nodes drawn as geometry, unsorted) and `out` receives the images
  // only; nothing is read back. The cost is still predicted from the frustum-culled items. Throws farfield::Error
  // with both `occlusion` and `geometry_objects` (the GPU culler does the occlusion culling of such a frame).
  ImageCacheFrameStats frame(gpu::Renderer& renderer, const Camera& camera, size_t frame_index,
                             std::vector<gpu::DrawItem>& out, const ImageCacheOcclusion* occlusion = nullptr,
                             std::vector<uint32_t>* geometry_objects = nullptr);

  size_t nodeCount() const { return nodes_.size(); }
  size_t textureBytes() const { return texture_bytes_; }

 private:
  struct Node {
    Box3 bounds;
    std::vector<uint32_t> objects;  // all objects below
    int left = -1, right = -1;
    std::vector<DVec3> samples;        // Shade's
    std::vector<DVec3> audit_points;   // mesh vertices (audit)
    uint64_t triangles = 0;
    uint32_t draws = 0;
    Vec3 mean_color{-1.0f};  // the objects' mean lit colour: the fill of the image's transparent texels
    std::unique_ptr<impostor::PlanarImpostor> image;
    std::unique_ptr<impostor::GpuLayeredImpostor> layered;
    Shaft shaft;              // the layered image's validity region
    size_t layered_bytes = 0;
    double layered_draw_ms = 0.0;  // bound of drawing the layered image (its plan's layers and fill)
    size_t last_used = 0;
    std::optional<size_t> regenerated_in;
    // This frame's items of the node's geometry in fallback_items_ (invalid nodes only): what drawing it as geometry
    // draws, frustum-culled and, with occlusion culling, without the items behind the occluders.
    size_t fallback_begin = 0, fallback_end = 0;
    // How far the eye moved from the capture eye while the current image was still valid, and the same for the
    // previous image, measured when it became invalid (< 0: no image has become invalid yet). With the eye's speed
    // it predicts how many frames a new image would serve (ImageCache::expectedReuse).
    DVec3 capture_eye{0.0};
    double reach = 0.0;
    double life = -1.0;
  };
  int build(std::vector<uint32_t> objects, int depth);
  void evict(size_t frame_index);
  bool hasImage(const Node& n) const { return n.image || n.layered; }
  size_t imageBytes(const Node& n) const;
  void dropImage(Node& n);
  double expectedReuse(const Node& n, const DVec3& eye, double theta) const;

  const scene::Scene& scene_;
  const gpu::GpuScene& gpu_scene_;
  ImageCacheOptions options_;
  std::vector<Node> nodes_;
  std::vector<uint32_t> always_geometry_;
  size_t texture_bytes_ = 0;
  std::optional<size_t> last_frame_;
  // The eye of the last frame and how far it moved from the frame before (< 0: unknown, at the first frame).
  DVec3 last_eye_{0.0};
  double eye_speed_ = -1.0;
  std::vector<gpu::DrawItem> scratch_;
  std::vector<Box3> scratch_bounds_;
  std::vector<gpu::DrawItem> visible_;
  std::vector<gpu::DrawItem> fallback_items_;
  std::vector<gpu::DrawItem> fallback_candidates_;  // one node's items before occlusion culling
  std::vector<Box3> fallback_bounds_;
  std::optional<gpu::OcclusionCuller> culler_;
};

}  // namespace farfield::runtime
