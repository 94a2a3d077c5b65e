// Potentially visible set of a viewing cell by item-buffer sampling, and the near/far segmentation of it
// (Decoret et al. 1999, sections 5.3 and 5.4).
#pragma once

#include <array>
#include <map>

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "farfield/core/math.h"
#include "farfield/gpu/occlusion_culler.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/renderer.h"
#include "farfield/scene/scene.h"
#include "farfield/urban/visibility_events.h"

namespace farfield::urban {

struct PvsOptions {
  float spacing = 2.0f;        // metres between sample points along the cell (both end points are sampled)
  int face_size = 128;         // pixels per side of each cube face (90-degree field of view)
  float near_plane = 0.25f;    // metres
  float far_plane = 20000.0f;  // metres
  // Reuse the 360-degree view of a sample point an earlier cell rendered (the same result: a view depends on the eye
  // only). A street's two cells have the same sample points, and cells meeting at a junction share it.
  bool reuse_viewpoints = true;
  // Each face draws the clusters that meet its frustum and face the eye (GpuScene::appendDrawItems). With occlusion
  // culling it first draws the nearest objects (through gpu::OcclusionCuller), reads their depth back, drops every
  // other object whose box lies behind that depth, then every cluster of the objects left that does. Each
  // test is exact (what it drops would draw no pixel), so the ids seen are those of drawing every object; off draws
  // every cluster in the frustum (the reference the tests and `farfield pvs-speed` compare against).
  bool occlusion_culling = true;
  // The first pass's share of the triangles of the objects in a face's frustum (nearest objects first).
  double occluder_share = 0.05;
};

struct Pvs {
  std::vector<uint32_t> ids;  // object ids seen from at least one sample point, sorted, no 0 (background)
  size_t sample_points = 0;
  size_t views = 0;           // cube faces rendered (6 per sample point not reused)
  size_t reused_points = 0;   // sample points whose view an earlier cell rendered (PvsOptions::reuse_viewpoints)
  uint64_t triangles_drawn = 0;  // over the faces rendered
  uint64_t objects_hidden = 0;   // over the faces: objects in a frustum dropped whole by occlusion culling
};

// What drawing one 360-degree view cost.
struct ViewpointStats {
  uint64_t triangles_drawn = 0;
  uint64_t objects_hidden = 0;  // per face, summed
};

// Points along [p, q]: both end points and evenly spaced ones between, no farther apart than `spacing`
// (ceil(|pq| / spacing) + 1 points; one point when p == q). The points of [q, p] are those of [p, q] in reverse
// order, bit for bit (so the two cells of a street share their views). Throws farfield::Error for a non-finite end point or a
// spacing that is not a positive finite number.
std::vector<Vec3> pvsSamplePoints(const Vec3& p, const Vec3& q, float spacing);

// The six 90-degree cameras of a 360-degree view from `eye` (+x, -x, +y, -y, +z, -z), face_size pixels square.
std::vector<Camera> cubeFaceCameras(const Vec3& eye, int face_size, float near_plane, float far_plane);

// Renders item buffers of a GpuScene. Needs a current OpenGL context for its whole life (gpu::sharedHeadlessContext()
// in tools and tests); the GpuScene must outlive it.
class PvsSampler {
 public:
  // Throws farfield::Error for a face size outside 1..4096 or bad near/far planes.
  explicit PvsSampler(const gpu::GpuScene& scene, const PvsOptions& options = {});

  // PVS of the cell from p to q: 360-degree views from pvsSamplePoints(p, q, spacing), union of the ids seen.
  // p and q are eye positions (the street's centreline end points at eye height above the ground).
  Pvs sample(const Vec3& p, const Vec3& q);
  // Adds to `seen` (indexed by id, grown as needed) the ids visible in a 360-degree view from `eye`.
  ViewpointStats sampleViewpoint(const Vec3& eye, std::vector<uint8_t>& seen);

  const PvsOptions& options() const { return options_; }

 private:
  const gpu::GpuScene* scene_;
  PvsOptions options_;
  gpu::Renderer renderer_;
  gpu::RenderTarget target_;
  // One face: the ids it sees are left in target_.
  ViewpointStats drawFace(const Camera& camera);
  ViewpointStats drawFaceCulled(const Camera& camera);

  gpu::OcclusionCuller culler_;             // the nearest objects' clusters
  std::vector<uint64_t> object_triangles_;  // per object id (index 0 unused)
  std::vector<gpu::DrawItem> face_items_;   // the clusters of one face's frustum
  std::vector<Box3> face_bounds_;           // their bounds in mesh space
  std::vector<gpu::DrawItem> drawn_items_;
  std::vector<gpu::ScreenBox> candidate_boxes_;  // the objects in the frustum: footprints
  std::vector<uint32_t> candidate_ids_;          // and ids
  std::vector<uint32_t> order_;                  // nearest first (gpu::splitNearestFirst)
  std::vector<uint32_t> face_ids_;
  std::vector<float> depth_;
  gpu::DepthPyramid pyramid_;
  std::map<std::array<uint32_t, 3>, std::vector<uint32_t>> views_;  // eye (float bits) -> ids seen, ascending
};

struct NearFarSplit {
  std::vector<uint32_t> near_ids;  // drawn as geometry
  std::vector<uint32_t> far_ids;   // replaced by image-based representations
};

// Near/far segmentation by distance: an object is near when its ground footprint (Object::footprint, or its world
// bounds' xy rectangle when it has none) comes within near_radius metres of the cell segment, far otherwise (an
// object without geometry and footprint is far). Ids keep the PVS order. Throws farfield::Error for an id out of
// range or a negative or non-finite radius.
NearFarSplit splitNearFar(const scene::Scene& scene, std::span<const uint32_t> pvs_ids, const CellSegment& cell,
                          float near_radius);
// Near/far segmentation by the cell's local model (Sillion 1997: the blocks touching the street): PVS members in
// `local_model_ids` are near, the others far. Ids keep the PVS order.
NearFarSplit splitNearFar(std::span<const uint32_t> pvs_ids, std::span<const uint32_t> local_model_ids);

}  // namespace farfield::urban
