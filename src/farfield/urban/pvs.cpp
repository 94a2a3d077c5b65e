// Decoret et al. 1999, "Multi-layered impostors for accelerated rendering", sections 5.3 (visibility culling by
// item-buffer sampling) and 5.4 (near/far model segmentation).
#include "farfield/urban/pvs.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <string>
#include <tuple>
#include <unordered_set>

#include "farfield/core/error.h"
#include "farfield/image/image.h"

namespace farfield::urban {

namespace {

bool finite3(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

}  // namespace

std::vector<Vec3> pvsSamplePoints(const Vec3& p, const Vec3& q, float spacing) {
  if (!finite3(p) || !finite3(q)) throw Error("PVS cell", "segment end point is not finite");
  if (!(spacing > 0.0f) || !std::isfinite(spacing))
    throw Error("PVS options", "sample spacing must be a positive number of metres, got " + std::to_string(spacing));
  const double length = glm::length(DVec3(q) - DVec3(p));
  if (length == 0.0) return {p};
  // One canonical direction, so that a street's two cells get the same points (reversed), bit for bit.
  if (std::tie(q.x, q.y, q.z) < std::tie(p.x, p.y, p.z)) {
    std::vector<Vec3> points = pvsSamplePoints(q, p, spacing);
    std::reverse(points.begin(), points.end());
    return points;
  }
  const size_t intervals = size_t(std::max(1.0, std::ceil(length / double(spacing))));
  std::vector<Vec3> points;
  points.reserve(intervals + 1);
  for (size_t i = 0; i <= intervals; ++i) {
    const double t = double(i) / double(intervals);
    points.push_back(Vec3(DVec3(p) + (DVec3(q) - DVec3(p)) * t));
  }
  points.back() = q;  // exactly the end point
  return points;
}

std::vector<Camera> cubeFaceCameras(const Vec3& eye, int face_size, float near_plane, float far_plane) {
  // A 90-degree square frustum per axis direction: the six tile the sphere of directions around the eye. The up
  // vector only has to be off the view axis: +z for the four horizontal faces, +y for the two vertical ones.
  static const Vec3 kDirections[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  std::vector<Camera> cameras;
  cameras.reserve(6);
  for (int f = 0; f < 6; ++f) {
    Camera camera;
    camera.eye = eye;
    camera.at = eye + kDirections[f];
    camera.up = f < 4 ? Vec3(0, 0, 1) : Vec3(0, 1, 0);
    camera.fov_y = float(kPi / 2.0);
    camera.width = camera.height = face_size;
    camera.near_plane = near_plane;
    camera.far_plane = far_plane;
    cameras.push_back(camera);
  }
  return cameras;
}

PvsSampler::PvsSampler(const gpu::GpuScene& scene, const PvsOptions& options) : scene_(&scene), options_(options) {
  if (options.face_size < 1 || options.face_size > 4096)
    throw Error("PVS options", "face size must be 1..4096 pixels, got " + std::to_string(options.face_size));
  if (!(options.near_plane > 0.0f) || !(options.far_plane > options.near_plane) || !std::isfinite(options.far_plane))
    throw Error("PVS options", "need 0 < near plane < far plane (finite)");
  if (!(options.occluder_share >= 0.0 && options.occluder_share <= 1.0))
    throw Error("PVS options", "occluder share must be in [0, 1], got " + std::to_string(options.occluder_share));
  target_ = gpu::RenderTarget(options.face_size, options.face_size);
  for (const gpu::ObjectDrawCost& cost : scene.objectDrawCosts()) object_triangles_.push_back(cost.triangles);
}

ViewpointStats PvsSampler::drawFace(const Camera& camera) {
  ViewpointStats stats;
  face_items_.clear();
  scene_->appendDrawItems({}, face_items_, camera);
  for (const gpu::DrawItem& item : face_items_) stats.triangles_drawn += item.triangleCount();
  renderer_.render(camera, face_items_, target_, gpu::RenderMode::ItemBuffer);
  return stats;
}

// Occlusion culling in two levels, so that a face's cost follows what it sees rather than the size of the city. The
// nearest objects (a share of the triangles in the frustum, and every object whose box reaches behind the eye) go
// through gpu::OcclusionCuller cluster by cluster: their nearest clusters first, then those not hidden behind them.
// Their depth is read back, and every other object is tested whole against it (one test per object: a street-level
// face of a city sees the first row of buildings, and the city behind it is dropped without looking at its
// clusters), then the clusters of the objects left. The same exactness argument throughout: whatever lies behind
// the depth already stored over its whole footprint draws no pixel (reversed Z, GL_GREATER).
ViewpointStats PvsSampler::drawFaceCulled(const Camera& camera) {
  ViewpointStats stats;
  const Mat4 view_proj = camera.viewProjection();
  const Frustum frustum = Frustum::fromMatrix(view_proj);
  const int size = options_.face_size;
  candidate_boxes_.clear();
  candidate_ids_.clear();
  for (const scene::Object& object : scene_->scene().objects) {
    if (object.world_bounds.empty() || !frustum.intersects(object.world_bounds)) continue;
    const gpu::ScreenBox box = gpu::projectBox(object.world_bounds, view_proj, size, size);
    if (!box.onScreen()) continue;  // covers no pixel centre: draws nothing
    candidate_boxes_.push_back(box);
    candidate_ids_.push_back(object.id);
  }
  order_.resize(candidate_ids_.size());
  for (size_t i = 0; i < order_.size(); ++i) order_[i] = uint32_t(i);
  const size_t split = gpu::splitNearestFirst(
      order_, candidate_boxes_, [&](uint32_t i) { return object_triangles_[candidate_ids_[i]]; },
      options_.occluder_share);
  face_ids_.clear();
  for (size_t k = 0; k < split; ++k) face_ids_.push_back(candidate_ids_[order_[k]]);
  target_.clear(Vec4(0.0f, 0.0f, 0.0f, 1.0f));  // an item buffer's background (Renderer::render)
  face_items_.clear();
  face_bounds_.clear();
  if (!face_ids_.empty()) scene_->appendDrawItems(face_ids_, face_items_, camera, &face_bounds_);
  for (const gpu::DrawItem& item : face_items_) stats.triangles_drawn += item.triangleCount();
  stats.triangles_drawn -=
      culler_.draw(renderer_, camera, face_items_, face_bounds_, target_, {}, gpu::RenderMode::ItemBuffer)
          .hidden_triangles;
  if (split == order_.size()) return stats;

  target_.readDepthRows(depth_);
  pyramid_.build(depth_, size, size);
  face_ids_.clear();
  for (size_t k = split; k < order_.size(); ++k) {
    if (pyramid_.hides(candidate_boxes_[order_[k]]))
      ++stats.objects_hidden;
    else
      face_ids_.push_back(candidate_ids_[order_[k]]);
  }
  if (face_ids_.empty()) return stats;
  face_items_.clear();
  face_bounds_.clear();
  scene_->appendDrawItems(face_ids_, face_items_, camera, &face_bounds_);
  drawn_items_.clear();
  for (size_t i = 0; i < face_items_.size(); ++i) {
    if (pyramid_.hides(gpu::projectBox(face_bounds_[i], view_proj * face_items_[i].transform, size, size))) continue;
    drawn_items_.push_back(face_items_[i]);
    stats.triangles_drawn += face_items_[i].triangleCount();
  }
  renderer_.draw(camera, drawn_items_, target_, gpu::RenderMode::ItemBuffer);
  return stats;
}

// Section 5.3: full 360-degree views from closely spaced points of the cell, the objects' ids in an item buffer;
// every id found is in the PVS. It is an estimate from below: an object seen only between the sample points, or
// only through gaps narrower than a pixel of the cube faces, is missed; the spacing and the face size bound that.
ViewpointStats PvsSampler::sampleViewpoint(const Vec3& eye, std::vector<uint8_t>& seen) {
  ViewpointStats stats;
  for (const Camera& camera : cubeFaceCameras(eye, options_.face_size, options_.near_plane, options_.far_plane)) {
    const ViewpointStats face = options_.occlusion_culling ? drawFaceCulled(camera) : drawFace(camera);
    stats.triangles_drawn += face.triangles_drawn;
    stats.objects_hidden += face.objects_hidden;
    const image::IdImage ids = target_.readIds();
    for (uint32_t id : ids.pixels()) {
      if (id == 0) continue;
      if (id >= seen.size()) seen.resize(size_t(id) + 1, 0);
      seen[id] = 1;
    }
  }
  return stats;
}

// A view depends on the eye only (the scene, the faces and the planes are the sampler's), so the ids a sample point
// saw are kept and reused by the next cell with that point: a whole-city bake renders each street's points once,
// not once per direction, and each junction's point once for all its streets.
Pvs PvsSampler::sample(const Vec3& p, const Vec3& q) {
  const std::vector<Vec3> points = pvsSamplePoints(p, q, options_.spacing);
  std::vector<uint8_t> seen;
  Pvs pvs;
  for (const Vec3& eye : points) {
    auto count = [&](const ViewpointStats& drawn) {
      pvs.views += 6;
      pvs.triangles_drawn += drawn.triangles_drawn;
      pvs.objects_hidden += drawn.objects_hidden;
    };
    if (!options_.reuse_viewpoints) {
      count(sampleViewpoint(eye, seen));
      continue;
    }
    const std::array<uint32_t, 3> key = {std::bit_cast<uint32_t>(eye.x), std::bit_cast<uint32_t>(eye.y),
                                         std::bit_cast<uint32_t>(eye.z)};
    auto it = views_.find(key);
    if (it != views_.end()) {
      ++pvs.reused_points;
    } else {
      std::vector<uint8_t> here;
      count(sampleViewpoint(eye, here));
      std::vector<uint32_t> ids;
      for (size_t id = 1; id < here.size(); ++id)
        if (here[id]) ids.push_back(uint32_t(id));
      it = views_.emplace(key, std::move(ids)).first;
    }
    for (uint32_t id : it->second) {
      if (id >= seen.size()) seen.resize(size_t(id) + 1, 0);
      seen[id] = 1;
    }
  }
  pvs.sample_points = points.size();
  for (size_t id = 1; id < seen.size(); ++id)
    if (seen[id]) pvs.ids.push_back(uint32_t(id));
  return pvs;
}

// Section 5.4 leaves the split to the target's rendering budget; two rules are offered. By distance: the cell's
// segment against each object's ground footprint, so a long block beside the street counts as near all along the
// street rather than by its centre; a radius is the natural knob for scenes without a street graph. By local model:
// Sillion's local model of a street (the blocks touching it) is exactly the geometry that must stay polygons,
// since any impostor of it would be seen from too close.
NearFarSplit splitNearFar(const scene::Scene& scene, std::span<const uint32_t> pvs_ids, const CellSegment& cell,
                          float near_radius) {
  if (!(near_radius >= 0.0f) || !std::isfinite(near_radius))
    throw Error("near/far split", "near radius must be a finite number >= 0 metres");
  NearFarSplit split;
  for (uint32_t id : pvs_ids) {
    if (id == 0 || id > scene.objects.size())
      throw Error("near/far split", "object id " + std::to_string(id) + " out of range (the scene has " +
                                        std::to_string(scene.objects.size()) + " objects, ids from 1)");
    const scene::Object& object = scene.objects[id - 1];
    Polygon2 footprint = object.footprint;
    if (footprint.empty() && !object.world_bounds.empty()) {
      const Box3& b = object.world_bounds;
      footprint = {{b.lo.x, b.lo.y}, {b.hi.x, b.lo.y}, {b.hi.x, b.hi.y}, {b.lo.x, b.hi.y}};
    }
    const double distance = distanceToCell(footprint, cell);  // infinity without a footprint
    (distance <= double(near_radius) ? split.near_ids : split.far_ids).push_back(id);
  }
  return split;
}

NearFarSplit splitNearFar(std::span<const uint32_t> pvs_ids, std::span<const uint32_t> local_model_ids) {
  const std::unordered_set<uint32_t> local(local_model_ids.begin(), local_model_ids.end());
  NearFarSplit split;
  for (uint32_t id : pvs_ids) (local.count(id) ? split.near_ids : split.far_ids).push_back(id);
  return split;
}

}  // namespace farfield::urban
