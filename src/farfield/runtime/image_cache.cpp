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

#include "farfield/core/check.h"
#include "farfield/core/error.h"
#include "farfield/core/error_bound.h"
#include "farfield/core/timer.h"
#include "farfield/impostor/layered_fill.h"
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
  if (!(options.cost_safety_factor >= 1.0)) throw Error("image cache", "cost_safety_factor must be >= 1");
  if (!(options.lost_frame_investment >= 0.0 && std::isfinite(options.lost_frame_investment)))
    throw Error("image cache", "lost_frame_investment must be a finite number >= 0");
  std::vector<uint32_t> small;
  for (const scene::Object& o : scene.objects) {
    if (o.world_bounds.empty()) continue;
    if (objectRadius(o.world_bounds) > options.max_object_radius) always_geometry_.push_back(o.id);
    else small.push_back(o.id);
  }
  nodes_.reserve(2 * small.size() / size_t(options.leaf_objects) + 2);
  if (!small.empty()) build(std::move(small), 0);
  const std::vector<gpu::ObjectDrawCost> costs = gpu_scene.objectDrawCosts();
  // Mean colour of each material (base colour times its texture's mean), lit by about the renderer's ambient plus
  // half its light: what a silhouette texel of the image should blend towards.
  std::vector<Vec3> material_color;
  for (const scene::Material& m : scene.materials) {
    Vec3 c(m.base_color);
    if (m.texture && m.texture->width() > 0) {
      DVec3 sum(0.0);
      const size_t step = std::max<size_t>(1, m.texture->pixelCount() / 4096);
      size_t n = 0;
      for (size_t i = 0; i < m.texture->pixelCount(); i += step, ++n) sum += DVec3(glm::dvec4(m.texture->pixels()[i]));
      c *= Vec3(sum / (255.0 * double(std::max<size_t>(n, 1))));
    }
    material_color.push_back(m.unlit ? c : c * 0.7f);
  }
  for (Node& n : nodes_) {
    DVec3 color_sum(0.0);
    double color_weight = 0.0;
    for (const uint32_t id : n.objects)
      for (const scene::Part& p : scene.objects[id - 1].parts) {
        const double w = double(scene.meshes[p.mesh].triangleCount());
        color_sum += w * DVec3(material_color[p.material]);
        color_weight += w;
      }
    if (color_weight > 0.0) n.mean_color = Vec3(color_sum / color_weight);
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

size_t ImageCache::imageBytes(const Node& n) const {
  return n.image ? n.image->textureBytes() : n.layered ? n.layered_bytes : 0;
}

void ImageCache::dropImage(Node& n) {
  texture_bytes_ -= imageBytes(n);
  n.image.reset();
  n.layered.reset();
  n.layered_bytes = 0;
  n.layered_draw_ms = 0.0;
}

void ImageCache::evict(size_t frame_index) {
  while (texture_bytes_ > options_.byte_budget) {
    Node* oldest = nullptr;
    for (Node& n : nodes_)
      if (hasImage(n) && n.last_used < frame_index && (!oldest || n.last_used < oldest->last_used)) oldest = &n;
    if (!oldest) break;
    dropImage(*oldest);
  }
}

// Frames a new image of n made now would serve after this one: the eye's displacement its images stay valid over,
// divided by the eye's speed. The displacement is the previous image's, measured; for a node none of whose images has
// become invalid yet, the parallax estimate theta d^2 / (2 r) of a planar image (points across the node's depth 2 r,
// at distance d, shift against each other by about 2 r x / d^2 when the eye moves x sideways), or for a layered
// image the way out of its shaft: d sin(apex / 2) sideways, (1 - approach) d towards. At the first frame, with no speed
// known, none: only an image cheaper than its geometry is made, and the others wait one frame for the speed; with the
// eye at rest, a thousand.
double ImageCache::expectedReuse(const Node& n, const DVec3& eye, double theta) const {
  if (eye_speed_ < 0.0) return 0.0;
  const double r = std::max(objectRadius(n.bounds), 1e-6);
  const double d = glm::length(eye - DVec3(n.bounds.center()));
  const double guess = options_.kind == CachedImageKind::Layered
                           ? d * std::min(std::sin(0.5 * options_.layered_apex_angle), 1.0 - options_.layered_approach)
                           : theta * d * d / (2.0 * r);
  const double life = n.life >= 0.0 ? n.life : guess;
  return eye_speed_ > 1e-9 ? std::min(life / eye_speed_, 1000.0) : 1000.0;
}

ImageCacheFrameStats ImageCache::frame(gpu::Renderer& renderer, const Camera& camera, size_t frame_index,
                                       std::vector<gpu::DrawItem>& out, const ImageCacheOcclusion* occlusion,
                                       std::vector<uint32_t>* geometry_objects) {
  if (occlusion && geometry_objects)
    throw Error("image cache", "occlusion culling on the CPU and geometry as objects for the GPU are exclusive");
  ImageCacheFrameStats st;
  const bool repeat = last_frame_ && *last_frame_ == frame_index;
  if (!repeat) {
    if (last_frame_) eye_speed_ = glm::length(DVec3(camera.eye) - last_eye_);  // per frame of the cache
    last_eye_ = DVec3(camera.eye);
  }
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

  // The near geometry. With occlusion culling its nearest items are drawn now, and the depth they leave hides the
  // rest of it and whole nodes of the cut.
  scratch_.clear();
  scratch_bounds_.clear();
  gpu_scene_.appendDrawItems(near_objects, scratch_, camera, occlusion ? &scratch_bounds_ : nullptr);
  uint64_t near_triangles = 0;
  for (const gpu::DrawItem& it : scratch_) near_triangles += it.triangleCount();
  size_t near_draws = scratch_.size();
  if (occlusion) {
    FF_CHECK(occlusion->target != nullptr && occlusion->draw_occluders);
    if (!culler_ || culler_->occluderShare() != occlusion->occluder_share) culler_.emplace(occlusion->occluder_share);
    visible_.clear();
    // The occluders hold their share of everything the frame could draw as geometry, the cut's nodes included (as
    // culled geometry's occluders would), not only of the near geometry.
    uint64_t cut_triangles = 0;
    for (const int i : cut) cut_triangles += nodes_[size_t(i)].triangles;
    const gpu::OcclusionStats os = culler_->cull(camera, scratch_, scratch_bounds_, *occlusion->target,
                                                 occlusion->draw_occluders, visible_, cut_triangles);
    st.occluders = os.occluders;
    st.hidden_items = os.hidden;
    st.hidden_triangles = os.hidden_triangles;
    near_triangles -= os.hidden_triangles;
    near_draws -= os.hidden;
    Stopwatch test;
    std::erase_if(cut, [&](int i) {
      const Node& n = nodes_[size_t(i)];
      if (!culler_->hidesWorldBox(n.bounds)) return false;
      ++st.hidden_nodes;
      st.hidden_node_triangles += n.triangles;
      return true;
    });
    st.occlusion_ms = os.readback_ms + os.pyramid_ms + test.milliseconds();
    out.insert(out.end(), visible_.begin(), visible_.end());
  } else if (geometry_objects) {
    geometry_objects->insert(geometry_objects->end(), near_objects.begin(), near_objects.end());
  } else {
    out.insert(out.end(), scratch_.begin(), scratch_.end());
  }

  // Requests: images missing or judged invalid by the metric (on a repeat, the nodes this frame regenerated).
  const gpu::CostModel& c = options_.cost;
  const double k = options_.cost_safety_factor;
  const gpu::LayeredCost& lc = options_.layered_cost;
  auto geometryMs = [&](uint64_t triangles, size_t draws) {
    return k * (c.ms_per_mtriangle * double(triangles) / 1e6 + c.ms_per_draw * double(draws));
  };
  // The geometry an invalid node would be drawn with, and its predicted cost: only what is in view and, with
  // occlusion culling, not behind the occluders (a node drawn as geometry behind a street's first row of buildings
  // costs what culled geometry costs, not its whole triangle count).
  fallback_items_.clear();
  auto fallbackMs = [&](Node& n) {
    n.fallback_begin = fallback_items_.size();
    if (occlusion) {
      fallback_candidates_.clear();
      fallback_bounds_.clear();
      gpu_scene_.appendDrawItems(n.objects, fallback_candidates_, camera, &fallback_bounds_);
      const gpu::OcclusionStats os = culler_->appendNotHidden(fallback_candidates_, fallback_bounds_, fallback_items_);
      st.hidden_fallback_items += os.hidden;
      st.hidden_fallback_triangles += os.hidden_triangles;
    } else {
      gpu_scene_.appendDrawItems(n.objects, fallback_items_, camera);
    }
    n.fallback_end = fallback_items_.size();
    uint64_t triangles = 0;
    for (size_t j = n.fallback_begin; j < n.fallback_end; ++j) triangles += fallback_items_[j].triangleCount();
    return geometryMs(triangles, n.fallback_end - n.fallback_begin);
  };
  auto appendFallback = [&](const Node& n) {
    if (geometry_objects)
      geometry_objects->insert(geometry_objects->end(), n.objects.begin(), n.objects.end());
    else
      out.insert(out.end(), fallback_items_.begin() + std::ptrdiff_t(n.fallback_begin),
                 fallback_items_.begin() + std::ptrdiff_t(n.fallback_end));
    ++st.geometry_nodes;
  };
  std::vector<RegenerationRequest> requests;
  std::vector<int> valid;
  for (const int i : cut) {
    Node& n = nodes_[size_t(i)];
    double ratio = std::numeric_limits<double>::infinity();
    if (n.layered && !(repeat && n.regenerated_in == frame_index)) {
      // Outside the shaft by angle or by distance: how far outside is the priority.
      const DVec3 to = eye - DVec3(n.shaft.apex);
      const double dist = glm::length(to);
      const double angle = std::acos(std::clamp(glm::dot(to / std::max(dist, 1e-9), DVec3(n.shaft.axis)), -1.0, 1.0));
      ratio = n.shaft.contains(camera.eye) ? 0.0
                                           : std::max({angle / (0.5 * n.shaft.apex_angle),
                                                       double(n.shaft.min_distance) / std::max(dist, 1e-9), 1.0 + 1e-9});
    }
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
    r.expected_reuse = expectedReuse(n, eye, theta);
    r.geometry_ms = fallbackMs(n);
    const double capture_geometry_ms = geometryMs(n.triangles, n.draws);  // an image is rendered from all of it
    const double side = std::min(double(options_.impostor.max_texels),
                                 2.0 * std::asin(std::min(1.0, 1.02 * objectRadius(n.bounds) /
                                                                   glm::length(eye - DVec3(n.bounds.center())))) /
                                     pixel_angle / options_.impostor.texel_pixels);
    // A layered capture renders the node once per layer: the plan it would get (pure arithmetic) says how many.
    double renders = 1.0;
    r.image_ms = k * c.ms_per_draw;
    r.regenerate_ms = -1.0;
    if (options_.kind == CachedImageKind::Layered) {
      const DVec3 centre(n.bounds.center());
      const double dist = glm::length(eye - centre);
      try {
        const Shaft shaft = Shaft::make(Vec3(centre), Vec3((eye - centre) / dist), float(options_.layered_apex_angle),
                                        float(options_.layered_approach * dist), "image cache shaft");
        impostor::LayeredOptions lo;
        lo.max_texture_size = options_.impostor.max_texels;
        lo.max_layers = 16;
        const impostor::LayeredPlan plan = impostor::planLayered(n.bounds, shaft, bound, lo);
        renders = double(std::max<size_t>(1, plan.layers.size()));
        if (lc.calibrated) {  // the calibrated capture (render, readback, crop, upload) and the layers' fill
          r.regenerate_ms = lc.captureBoundMs(double(n.triangles) * renders, renders, double(plan.texels));
          r.image_ms = k * c.ms_per_draw * double(plan.draws()) +
                       lc.drawBoundMs(renders, impostor::layeredFillPixels(plan, dist, bound));
        }
      } catch (const Error&) {
        renders = 1.0;  // too near for layers: regenerating draws the geometry (see below)
      }
    }
    if (r.regenerate_ms < 0.0)
      r.regenerate_ms =
          renders * (capture_geometry_ms + options_.regeneration_overhead_ms + k * c.ms_per_mpixel * side * side / 1e6);
    requests.push_back(r);
  }
  double base = k * (c.base_ms + c.ms_per_mpixel * pixels / 1e6 + c.ms_per_mtriangle * double(near_triangles) / 1e6 +
                     c.ms_per_draw * double(near_draws) + c.ms_per_draw * double(valid.size()));
  for (const int i : valid) base += nodes_[size_t(i)].layered_draw_ms;  // the valid layered images' fill
  const RegenerationSchedule schedule =
      scheduleRegenerations(requests, base, options_.t_max_ms, options_.max_regenerations,
                            options_.lost_frame_investment * options_.t_max_ms,
                            options_.pay_back && (c.ms_per_mtriangle > 0.0 || c.ms_per_draw > 0.0));
  st.predicted_ms = schedule.predicted_ms;
  st.lost = schedule.lost;

  for (const uint32_t i : schedule.regenerate) {
    Node& n = nodes_[i];
    // How far the image being replaced stayed valid (not on a repeat of the frame that made it).
    if (hasImage(n) && n.regenerated_in != frame_index) n.life = n.reach;
    n.capture_eye = eye;
    n.reach = 0.0;
    dropImage(n);
    if (options_.kind == CachedImageKind::Layered) {
      const DVec3 centre(n.bounds.center());
      const double dist = glm::length(eye - centre);
      n.shaft = Shaft::make(Vec3(centre), Vec3((eye - centre) / dist), float(options_.layered_apex_angle),
                            float(options_.layered_approach * dist), "image cache shaft");
      impostor::LayeredOptions lo;
      lo.max_texture_size = options_.impostor.max_texels;
      lo.max_layers = 16;
      impostor::LayeredPlan plan;
      try {
        plan = impostor::planLayered(n.bounds, n.shaft, bound, lo);
      } catch (const Error&) {
        // The shaft's minimum distance does not clear the cluster (its layers' quads reach out further than its
        // box): too near for a layered image; its geometry is drawn.
        appendFallback(n);
        continue;
      }
      const impostor::LayeredImpostor captured =
          impostor::cropLayered(impostor::captureLayered(renderer, gpu_scene_, n.objects, plan));
      n.layered = std::make_unique<impostor::GpuLayeredImpostor>(captured);
      n.layered_bytes = n.layered->gpuBytes();
      // Valid while the eye stays in the shaft: bounded from its nearest viewpoints, over the tiles drawn.
      n.layered_draw_ms =
          lc.drawBoundMs(double(plan.quads()), impostor::layeredFillPixels(captured.plan, 0.0, bound));
      texture_bytes_ += n.layered_bytes;
      st.texels_written_bytes += size_t(captured.plan.texels) * 4;
      st.uploaded_bytes += n.layered_bytes;  // read back per layer, cropped, uploaded again
    } else {
      scratch_.clear();
      gpu_scene_.appendDrawItems(n.objects, scratch_);
      n.image = std::make_unique<impostor::PlanarImpostor>(renderer, scratch_, n.bounds, n.samples, camera.eye,
                                                           pixel_angle, options_.impostor, n.mean_color);
      texture_bytes_ += n.image->textureBytes();
      st.texels_written_bytes += n.image->texelBytes();
      st.uploaded_bytes += n.image->meshBytes();
    }
    n.regenerated_in = frame_index;
    ++st.regenerations;
    valid.push_back(int(i));
  }
  for (const int i : valid) {
    Node& n = nodes_[size_t(i)];
    n.reach = std::max(n.reach, glm::length(eye - n.capture_eye));
    n.last_used = frame_index;
    if (n.layered) n.layered->appendDrawItems(out, 0);
    else n.image->appendDrawItems(out, 0);
    ++st.images_drawn;
  }
  for (const uint32_t i : schedule.geometry) appendFallback(nodes_[i]);
  evict(frame_index);
  st.texture_bytes = texture_bytes_;
  return st;
}

}  // namespace farfield::runtime
