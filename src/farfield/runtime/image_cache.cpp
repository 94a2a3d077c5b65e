// Hierarchical image cache (Shade et al. 1996; steed-ibr-impostors-lecture, part 2, "Impostors", "Static or dynamic
// impostors?": texture memory acts as a cache, no preprocessing, high bus traffic).
//
// Why a k-d hierarchy of its own and not the scene BVH: the image cache needs, per node, the list of its objects and
// their sample points, and a split that keeps siblings compact (a median split on the longest axis), which the BVH's
// SAH build does not promise and its interface does not expose.
#include "farfield/runtime/image_cache.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "farfield/core/error.h"
#include "farfield/core/error_bound.h"
#include "farfield/runtime/regeneration_scheduler.h"

namespace farfield::runtime {
namespace {

double objectRadius(const Box3& b) { return 0.5 * glm::length(DVec3(b.hi) - DVec3(b.lo)); }

void thin(std::vector<DVec3>& points, size_t keep) {
  if (points.size() <= keep || keep == 0) return;
  std::vector<DVec3> out;
  out.reserve(keep);
  for (size_t i = 0; i < keep; ++i) out.push_back(points[i * points.size() / keep]);
  points = std::move(out);
}

}  // namespace

ImageCache::ImageCache(const scene::Scene& scene, const gpu::GpuScene& gpu_scene, const ImageCacheOptions& options)
    : scene_(scene), gpu_scene_(gpu_scene), options_(options) {
  if (!(options.error_px > 0.0)) throw Error("image cache", "error_px must be > 0");
  if (options.leaf_objects < 1) throw Error("image cache", "leaf_objects must be >= 1");
  if (!(options.min_distance_radii > 1.0)) throw Error("image cache", "min_distance_radii must be > 1");
  if (options.shade_samples < 1) throw Error("image cache", "shade_samples must be >= 1");
  std::vector<uint32_t> small;
  for (const scene::Object& o : scene.objects) {
    if (o.world_bounds.empty()) continue;
    if (objectRadius(o.world_bounds) > options.max_object_radius) always_geometry_.push_back(o.id);
    else small.push_back(o.id);
  }
  nodes_.reserve(2 * small.size() / size_t(options.leaf_objects) + 2);
  if (!small.empty()) build(std::move(small), 0);
  const std::vector<gpu::ObjectDrawCost> costs = gpu_scene.objectDrawCosts();
  for (Node& n : nodes_) {
    for (const uint32_t id : n.objects) {
      n.triangles += costs[id].triangles;
      n.draws += costs[id].draws;
      const Box3& b = scene.objects[id - 1].world_bounds;
      for (int i = 0; i < 8; ++i)
        n.samples.push_back(DVec3(i & 1 ? b.hi.x : b.lo.x, i & 2 ? b.hi.y : b.lo.y, i & 4 ? b.hi.z : b.lo.z));
    }
    thin(n.samples, size_t(options.shade_samples));
    if (options.audit_samples > 0) {
      for (const uint32_t id : n.objects) {
        const scene::Object& o = scene.objects[id - 1];
        for (const scene::Part& p : o.parts)
          for (const Vec3& v : scene.meshes[p.mesh].positions) n.audit_points.push_back(DVec3(o.transform * Vec4(v, 1)));
      }
      thin(n.audit_points, size_t(options.audit_samples));
    }
  }
}

ImageCache::~ImageCache() = default;

int ImageCache::build(std::vector<uint32_t> objects, int depth) {
  const int index = int(nodes_.size());
  nodes_.emplace_back();
  Box3 box;
  for (const uint32_t id : objects) box.expand(scene_.objects[id - 1].world_bounds);
  nodes_[size_t(index)].bounds = box;
  if (int(objects.size()) > options_.leaf_objects && depth < 40) {
    const Vec3 e = box.hi - box.lo;
    const int axis = e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
    const size_t mid = objects.size() / 2;
    std::nth_element(objects.begin(), objects.begin() + std::ptrdiff_t(mid), objects.end(), [&](uint32_t a, uint32_t b) {
      return scene_.objects[a - 1].world_bounds.center()[axis] < scene_.objects[b - 1].world_bounds.center()[axis];
    });
    std::vector<uint32_t> lo(objects.begin(), objects.begin() + std::ptrdiff_t(mid));
    std::vector<uint32_t> hi(objects.begin() + std::ptrdiff_t(mid), objects.end());
    const int l = build(std::move(lo), depth + 1);
    const int r = build(std::move(hi), depth + 1);
    nodes_[size_t(index)].left = l;
    nodes_[size_t(index)].right = r;
  }
  nodes_[size_t(index)].objects = std::move(objects);
  return index;
}

void ImageCache::evict(size_t frame_index) {
  while (texture_bytes_ > options_.byte_budget) {
    Node* oldest = nullptr;
    for (Node& n : nodes_)
      if (n.image && n.last_used < frame_index && (!oldest || n.last_used < oldest->last_used)) oldest = &n;
    if (!oldest) break;
    texture_bytes_ -= oldest->image->textureBytes();
    oldest->image.reset();
  }
}

ImageCacheFrameStats ImageCache::frame(gpu::Renderer& renderer, const Camera& camera, size_t frame_index,
                                       std::vector<gpu::DrawItem>& out) {
  ImageCacheFrameStats st;
  const bool repeat = last_frame_ && *last_frame_ == frame_index;
  last_frame_ = frame_index;
  const ErrorBound bound = ErrorBound::forCamera(options_.error_px, camera);
  const double theta = bound.angle();
  const double pixel_angle = bound.centrePixelAngle();
  const Frustum frustum = Frustum::fromMatrix(camera.viewProjection());
  const DVec3 eye(camera.eye);
  const double pixels = double(camera.width) * camera.height;

  // The cut: the highest nodes in view that are far enough; nearer leaves are geometry.
  std::vector<uint32_t> near_objects = always_geometry_;
  std::vector<int> cut;
  std::vector<int> stack;
  if (!nodes_.empty()) stack.push_back(0);
  while (!stack.empty()) {
    const int i = stack.back();
    stack.pop_back();
    const Node& n = nodes_[size_t(i)];
    if (!frustum.intersects(n.bounds)) continue;
    const double r = objectRadius(n.bounds);
    if (glm::length(eye - DVec3(n.bounds.center())) > options_.min_distance_radii * r) {
      cut.push_back(i);
    } else if (n.left < 0) {
      near_objects.insert(near_objects.end(), n.objects.begin(), n.objects.end());
    } else {
      stack.push_back(n.right);
      stack.push_back(n.left);
    }
  }
  st.near_objects = near_objects.size();

  // Requests: images missing or judged invalid by the metric (on a repeat, the nodes this frame regenerated).
  const gpu::CostModel& c = options_.cost;
  auto geometryMs = [&](const Node& n) {
    return c.ms_per_mtriangle * double(n.triangles) / 1e6 + c.ms_per_draw * double(n.draws);
  };
  std::vector<RegenerationRequest> requests;
  std::vector<int> valid;
  for (const int i : cut) {
    Node& n = nodes_[size_t(i)];
    double ratio = std::numeric_limits<double>::infinity();
    if (n.image && !(repeat && n.regenerated_in == frame_index)) {
      const double e = n.image->error(options_.metric, camera.eye);
      ratio = e / theta;
      if (options_.audit_samples > 0 && !n.audit_points.empty()) {
        const bool measured_ok = n.image->shadeErrorOf(n.audit_points, camera.eye) <= theta;
        ++st.audited;
        if (ratio > 1.0 && measured_ok) ++st.unneeded;
        if (ratio <= 1.0 && !measured_ok) ++st.missed;
      }
    }
    if (ratio <= 1.0) {
      valid.push_back(i);
      continue;
    }
    RegenerationRequest r;
    r.node = uint32_t(i);
    r.error_ratio = ratio;
    r.geometry_ms = geometryMs(n);
    const double side = std::min(double(options_.impostor.max_texels),
                                 2.0 * std::asin(std::min(1.0, 1.02 * objectRadius(n.bounds) /
                                                                   glm::length(eye - DVec3(n.bounds.center())))) /
                                     pixel_angle / options_.impostor.texel_pixels);
    r.regenerate_ms = r.geometry_ms + options_.regeneration_overhead_ms + c.ms_per_mpixel * side * side / 1e6;
    r.image_ms = c.ms_per_draw;
    requests.push_back(r);
  }
  double base = c.base_ms + c.ms_per_mpixel * pixels / 1e6;
  {
    uint64_t tris = 0, draws = 0;
    scratch_.clear();
    gpu_scene_.appendDrawItems(near_objects, scratch_, camera);
    for (const gpu::DrawItem& it : scratch_) tris += it.triangleCount();
    draws = scratch_.size();
    base += c.ms_per_mtriangle * double(tris) / 1e6 + c.ms_per_draw * double(draws) + c.ms_per_draw * double(valid.size());
    out.insert(out.end(), scratch_.begin(), scratch_.end());
  }
  const RegenerationSchedule schedule =
      scheduleRegenerations(requests, base, options_.t_max_ms, options_.max_regenerations);
  st.predicted_ms = schedule.predicted_ms;

  for (const uint32_t i : schedule.regenerate) {
    Node& n = nodes_[i];
    scratch_.clear();
    gpu_scene_.appendDrawItems(n.objects, scratch_);
    if (n.image) texture_bytes_ -= n.image->textureBytes();
    n.image = std::make_unique<impostor::PlanarImpostor>(renderer, scratch_, n.bounds, n.samples, camera.eye,
                                                         pixel_angle, options_.impostor);
    texture_bytes_ += n.image->textureBytes();
    n.regenerated_in = frame_index;
    ++st.regenerations;
    st.texels_written_bytes += n.image->texelBytes();
    st.uploaded_bytes += n.image->meshBytes();
    valid.push_back(int(i));
  }
  for (const int i : valid) {
    Node& n = nodes_[size_t(i)];
    n.last_used = frame_index;
    n.image->appendDrawItems(out, 0);
    ++st.images_drawn;
  }
  for (const uint32_t i : schedule.geometry) {
    gpu_scene_.appendDrawItems(nodes_[i].objects, out, camera);
    ++st.geometry_nodes;
  }
  evict(frame_index);
  st.texture_bytes = texture_bytes_;
  return st;
}

}  // namespace farfield::runtime
