// Layered environment-map impostors of a box view cell (environment_map.h derives the spacing).
#include "farfield/impostor/environment_map.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "farfield/core/error.h"

namespace farfield::impostor {
namespace {

constexpr std::array<Vec3, 6> kFaceAxes = {Vec3(1, 0, 0), Vec3(-1, 0, 0), Vec3(0, 1, 0),
                                           Vec3(0, -1, 0), Vec3(0, 0, 1), Vec3(0, 0, -1)};

// The box's range of dot(x - c, axis) for a unit coordinate axis.
std::pair<double, double> depthRange(const Box3& b, const Vec3& c, int face) {
  const int k = face / 2;
  const double lo = double(b.lo[k]) - double(c[k]), hi = double(b.hi[k]) - double(c[k]);
  return face % 2 == 0 ? std::pair{lo, hi} : std::pair{-hi, -lo};
}

// The smallest |x_k - c_k| over the box (0 when it spans c_k).
double minAbs(const Box3& b, const Vec3& c, int k) {
  const double lo = double(b.lo[k]) - double(c[k]), hi = double(b.hi[k]) - double(c[k]);
  return lo > 0.0 ? lo : hi < 0.0 ? -hi : 0.0;
}

struct FaceObject {
  uint32_t id;
  double t_lo, t_hi;  // its depth range in the face, t_lo >= d
  Box3 bounds;
};

EnvMapFace planFace(int face, const Vec3& c, double d, double r, double dw, std::vector<FaceObject> objects,
                    const ErrorBound& bound, const EnvMapOptions& options, bool* capped) {
  EnvMapFace out;
  out.face = face;
  std::sort(objects.begin(), objects.end(), [](const FaceObject& a, const FaceObject& b) { return a.id < b.id; });
  double t_end = d;
  Box3 box;
  for (const FaceObject& o : objects) {
    out.objects.push_back(o.id);
    t_end = std::max(t_end, o.t_hi);
    box.expand(o.bounds);
  }
  const Vec3 a = kFaceAxes[size_t(face)];
  const double L = t_end + std::max(1.0, 0.01 * t_end);  // the plan's apex lies beyond every layer
  LayeredPlan& plan = out.plan;
  plan.shaft = Shaft::make(c + float(L) * a, -a, float(0.5 * kPi), float(L), "environment-map face");
  plan.box = box;
  plan.capture_eye = c;
  plan.camera_up = std::abs(a.z) < 0.9f ? Vec3(0.0f, 0.0f, 1.0f) : Vec3(0.0f, 1.0f, 0.0f);
  const DVec3 forward(a);
  const DVec3 right = glm::normalize(glm::cross(forward, DVec3(plan.camera_up)));
  plan.right = Vec3(right);
  plan.up = Vec3(glm::cross(right, forward));
  plan.z_lo = float(L - t_end);
  plan.z_hi = float(L - d);
  plan.radius = r;
  plan.bound_angle = bound.angle();
  plan.error_angle = std::asin(std::min(1.0, 0.5 * r * dw));
  plan.id_textures = false;
  plan.solid_slices = true;
  plan.dilate_texels = options.dilate_texels;

  const double wanted = bound.cornerPixelAngle() * std::min(options.texel_pixels, bound.pixels);
  const double focal = bound.focalPixels();
  const double w0 = 1.0 / (d - r), w_end = 1.0 / (t_end - r);
  const int count = std::max(1, int(std::ceil((w0 - w_end) / dw - 1e-9)));
  // Far to near: the slab k from the far end first.
  for (int k = count - 1; k >= 0; --k) {
    const double w_hi = w0 - dw * k, w_lo = std::max(w_end, w0 - dw * (k + 1));
    const double t_lo = r + 1.0 / w_hi, t_hi = r + 1.0 / w_lo, t_m = r + 2.0 / (w_hi + w_lo);
    std::vector<uint32_t> in_slab;
    for (const FaceObject& o : objects)
      if (o.t_lo <= t_hi && o.t_hi >= t_lo) in_slab.push_back(o.id);
    if (in_slab.empty()) continue;
    double s = wanted * (t_m - r);
    int n = int(std::ceil(2.0 * t_m / s));
    if (n > options.max_texture_size) {
      n = options.max_texture_size;
      s = 2.0 * t_m / double(n);
      *capped = true;
    }
    LayerPlan layer;
    layer.z_lo = float(L - t_hi);
    layer.z_hi = float(L - t_lo);
    layer.depth = float(L - t_m);
    layer.width = layer.height = n;
    layer.half_u = layer.half_v = float(0.5 * n * s);
    layer.fov_y = float(2.0 * std::atan(0.5 * n * s / t_m));
    plan.texture_bytes += size_t(n) * size_t(n) * 4;  // replaced by the atlases' below
    plan.texels += uint64_t(n) * uint64_t(n);
    plan.mesh_bytes += kLayerQuadBytes;
    plan.texel_angle = std::max(plan.texel_angle, s / (t_m - r));
    const double gap = t_m - r;
    plan.fill_pixels += std::min(double(bound.width) * double(bound.height),
                                 4.0 * double(layer.half_u) * double(layer.half_v) * focal * focal / (gap * gap));
    plan.layers.push_back(layer);
    out.layer_objects.push_back(std::move(in_slab));
  }
  plan.spacing = 0.0;
  // Each layer's cover from the boxes of the objects its slab meets (the tiles GpuLayeredImpostor will draw).
  for (size_t i = 0; i < plan.layers.size(); ++i) {
    std::vector<Box3> parts;
    for (uint32_t id : out.layer_objects[i])
      parts.push_back(std::lower_bound(objects.begin(), objects.end(), id,
                                       [](const FaceObject& o, uint32_t v) { return o.id < v; })
                          ->bounds);
    plan.layers[i].cover = plannedLayerCover(plan, i, parts);
  }
  packAtlases(plan);
  plan.texture_bytes = 0;
  for (const IVec2& s : plan.atlas_sizes) plan.texture_bytes += size_t(s.x) * size_t(s.y) * 4;
  return out;
}

}  // namespace

size_t EnvMapPlan::layers() const {
  size_t n = 0;
  for (const EnvMapFace& f : faces) n += f.plan.layers.size();
  return n;
}

uint64_t EnvMapPlan::texels() const {
  uint64_t n = 0;
  for (const EnvMapFace& f : faces) n += f.plan.texels;
  return n;
}

size_t EnvMapPlan::bytes() const {
  size_t n = 0;
  for (const EnvMapFace& f : faces) n += f.plan.bytes();
  return n;
}

size_t EnvMapPlan::draws() const {
  size_t n = 0;
  for (const EnvMapFace& f : faces) n += f.plan.draws();
  return n;
}

EnvMapPlan planEnvironmentMap(const Box3& cell, double far_distance, std::span<const EnvMapObject> objects,
                              const ErrorBound& bound, const EnvMapOptions& options) {
  if (cell.empty() || !isFinite(cell.lo) || !isFinite(cell.hi))
    throw Error("environment-map cell", "empty or not finite");
  bound.validate("environment-map error bound");
  if (!(bound.pixels > 0.0)) throw Error("environment-map error bound", "needs more than 0 pixels");
  if (!(options.texel_pixels > 0.0) || !std::isfinite(options.texel_pixels))
    throw Error("environment-map options", "texel_pixels must be > 0");
  if (options.max_texture_size < 1 || options.max_texture_size > 16384)
    throw Error("environment-map options", "max_texture_size must be 1..16384");
  if (options.dilate_texels < 0 || options.dilate_texels > 16)
    throw Error("environment-map options", "dilate_texels must be 0..16");
  EnvMapPlan plan;
  plan.cell = cell;
  plan.centre = cell.center();
  plan.radius = 0.5 * double(glm::length(cell.extent()));
  plan.far_distance = far_distance;
  if (!std::isfinite(far_distance) || far_distance <= plan.radius * 1.001)
    throw Error("environment-map far-field distance",
                std::to_string(far_distance) + " m is not beyond the cell's half-diagonal " +
                    std::to_string(plan.radius) + " m: viewpoints would reach the layers");
  plan.slab_width_w = 2.0 * std::sin(bound.angle()) / plan.radius;
  plan.error_angle = std::asin(std::min(1.0, 0.5 * plan.radius * plan.slab_width_w));

  const Vec3 c = plan.centre;
  const double d = far_distance;
  Box3 cube;
  cube.lo = c - Vec3(float(d));
  cube.hi = c + Vec3(float(d));
  std::array<std::vector<FaceObject>, 6> per_face;
  for (const EnvMapObject& o : objects) {
    if (o.id == 0) throw Error("environment-map objects", "object id 0 (ids start at 1)");
    if (o.bounds.empty() || !isFinite(o.bounds.lo) || !isFinite(o.bounds.hi))
      throw Error("environment-map object " + std::to_string(o.id), "empty or non-finite bounds");
    if (o.bounds.overlaps(cube)) {
      plan.near_objects.push_back(o.id);
      continue;
    }
    for (int f = 0; f < 6; ++f) {
      const auto [t_lo, t_hi] = depthRange(o.bounds, c, f);
      if (t_hi < d) continue;
      // Conservative frustum test: the face's frustum holds the points with |u|, |v| <= t (u, v the other axes).
      const int k = f / 2, u = (k + 1) % 3, v = (k + 2) % 3;
      if (minAbs(o.bounds, c, u) > t_hi || minAbs(o.bounds, c, v) > t_hi) continue;
      per_face[size_t(f)].push_back({o.id, std::max(d, t_lo), t_hi, o.bounds});
    }
  }
  std::sort(plan.near_objects.begin(), plan.near_objects.end());
  for (int f = 0; f < 6; ++f) {
    if (per_face[size_t(f)].empty()) continue;
    plan.faces.push_back(planFace(f, c, d, plan.radius, plan.slab_width_w, std::move(per_face[size_t(f)]), bound,
                                  options, &plan.resolution_capped));
  }
  return plan;
}

EnvMapLayersInView envMapLayersInView(const EnvMapPlan& plan, const Frustum& view, const ErrorBound& frame) {
  EnvMapLayersInView in_view;
  const double focal = frame.focalPixels();
  const double cap = double(frame.width) * double(frame.height);
  for (const EnvMapFace& face : plan.faces) {
    const LayeredPlan& p = face.plan;
    for (const LayerPlan& layer : p.layers) {
      // The quad's plane lies `depth` from the apex along the axis, t_m = L - depth from the cell's centre.
      const Vec3 centre = p.shaft.apex + p.shaft.axis * layer.depth + p.right * layer.offset_u + p.up * layer.offset_v;
      const Vec3 du = p.right * layer.half_u, dv = p.up * layer.half_v;
      Box3 quad = Box3::fromPoints(centre - du - dv, centre + du + dv);
      quad.expand(centre + du - dv);
      quad.expand(centre - du + dv);
      if (!view.intersects(quad)) continue;
      const double t_m = double(p.shaft.min_distance) - double(layer.depth);
      const double gap = std::max(t_m - plan.radius, 1e-2 * t_m);
      ++in_view.quads;
      in_view.fill_pixels +=
          std::min(4.0 * double(layer.half_u) * double(layer.half_v) * focal * focal / (gap * gap), cap) *
          double(layer.cover);
    }
  }
  return in_view;
}

double envMapPointError(const LayeredPlan& face_plan, const Vec3& eye, const Vec3& p) {
  const DVec3 c(face_plan.capture_eye), a(-face_plan.shaft.axis), P(p);
  const double L = face_plan.shaft.min_distance;
  const double t = glm::dot(P - c, a);
  for (const LayerPlan& layer : face_plan.layers) {
    const double t_lo = L - double(layer.z_hi), t_hi = L - double(layer.z_lo);
    if (t < t_lo || t > t_hi) continue;
    const double t_m = L - double(layer.depth);
    const DVec3 drawn = c + (P - c) * (t_m / t);
    const DVec3 to_p = glm::normalize(P - DVec3(eye)), to_drawn = glm::normalize(drawn - DVec3(eye));
    return std::acos(std::clamp(glm::dot(to_p, to_drawn), -1.0, 1.0));
  }
  throw Error("environment-map point", "lies in no layer of the face");
}

}  // namespace farfield::impostor
