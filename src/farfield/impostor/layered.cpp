// Layered impostors for a shaft view cell (Jeschke et al. 2005, sections 4 and 6.2; the lecture's layered impostors).
//
// Capture: perspective, from E = apex + d * axis (d = the shaft's minimum distance), not orthographic along the axis.
// - Error. A point P at distance delta (along the axis) from its layer plane is drawn at Q, where E's ray through P
//   meets the plane: |Q - P| = delta / cos(gamma), gamma the ray's angle to the axis. Seen from a viewpoint V, the
//   angle between P and Q is the integral along the segment of h / rho^2 (h = the distance from V to the ray's line,
//   rho = the distance from V to the point: the same integral as validity.h's triangle bound). With the ray through E,
//   h <= |V - E|, which vanishes at E and grows with the distance from it, while rho^2 grows too: the viewpoints that
//   see the most parallax (the nearest) are the ones whose rays agree best with E's. An orthographic capture has
//   h = rho sin(psi) and an error delta sin(psi) / rho, largest exactly there. The bounds of the two (below; for
//   parallel rays gamma = 0, no spread, and only the first term) differ by less than a quarter on the tests' cluster
//   (21 m deep, 20 m wide): from E 15-20 % smaller for apex angles up to 45 degrees near the cluster (d = 60 m; the
//   paper's shafts are 11.25-90 degrees), within 10 % far away, 10-20 % larger for 90 degrees and more near it.
// - Renderer. gpu::Renderer draws through core::Camera, a pinhole. Its near and far planes are planes of constant
//   depth along the axis, so they clip to a slab exactly, and a plane of constant depth maps affinely onto the image,
//   so a 4-vertex quad with corner uvs shows every texel where E saw it (perspective-correct interpolation).
//
// Spacing. Frame: z = dot(x - apex, axis); the box spans [z_lo, z_hi], lateral distances up to L from the axis.
// Every point X that is drawn or captured (P, Q, the segment between) has |X - apex| <= r' with
//   r' = sqrt((L (d - z_lo) / (d - z_hi))^2 + max(z_lo^2, z_hi^2))     (E's rays spread by at most (d-z_lo)/(d-z_hi))
// and its ray's angle to the axis is at most gamma = atan(L / (d - z_hi)). A viewpoint V at distance D >= d from the
// apex within theta = apex_angle / 2 of the axis has rho >= D - r', and two bounds of the integrand hold:
//   (1) h / rho = sin(psi) with psi <= gamma + theta + asin(r' / D)           (angle of the ray vs the view ray)
//   (2) h <= |V - E| <= sqrt(D^2 + d^2 - 2 D d cos(theta))                    (V on the cone's rim is farthest from E)
// so the angle is at most delta * K with
//   K = 1 / cos(gamma) * max over D >= d of min( sin(min(pi/2, gamma + theta + asin(r'/D))) / (D - r'),
//                                                sqrt(D^2 + d^2 - 2 D d cos(theta)) / (D - r')^2 ).
// The first term falls with D; the second is evaluated on geometric intervals [D_a, D_b] with its numerator at D_b and
// its denominator at D_a (an upper bound over the interval), stopping once the first term at D_a is below the maximum
// found (nothing beyond can exceed it). A point is at most half a slab from its plane, so slabs of width
//   spacing <= 2 * bound.angle() / K           (bound.angle() / K with bound_cracks)
// keep the error under the bound; layers = ceil((z_hi - z_lo) / max_spacing), evenly spaced, planes at slab centres.
// tests/impostor/layered_test.cpp checks K against the angle measured between P and Q from viewpoints sampled in 72
// shafts: it holds in all, the worst measured reaches 0.98 of it, and every shaft at least 0.2.
//
// Solid slices: each slab is rendered with every material double-sided, so a slab that cuts a closed object shows its
// inside: a layer holds the object's cross-section, and a face that E sees edge-on or from behind but another
// viewpoint of the shaft sees (a wall along the axis) is stood in for by the slices' insides, in the right place
// within the bound though not in its own shade. Single-sided slices leave those faces out (the test counts three
// times as many wrong pixels). captureView (capture.h) renders the scene's materials as they are and clears to the
// sky, so the passes are written out here with the same renderer and render target.
//
// Resolution: a texel of size s at distance >= d - r' subtends at most s / (d - r'); s = texel angle * (d - r').
#include "farfield/impostor/layered.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <unordered_map>

#include "farfield/core/camera.h"
#include "farfield/core/check.h"
#include "farfield/core/error.h"
#include "farfield/core/timer.h"
#include "farfield/gpu/render_target.h"
#include "farfield/scene/mesh.h"

namespace farfield::impostor {
// Shelf packing of the layer images, tallest first: a layer goes right of the previous one on the current shelf, or
// starts a new shelf below it, or a new atlas when the shelf would pass kAtlasSide. Atlases are as small as their
// contents (plus padding). Deterministic: planLayered and GpuLayeredImpostor agree on the layout.
void packAtlases(LayeredPlan& plan) {
  plan.atlas_spots.assign(plan.layers.size(), {});
  plan.atlas_sizes.clear();
  int x = 0, y = 0, shelf = 0;
  IVec2 used(0);
  const auto close = [&] {
    if (used.x > 0) plan.atlas_sizes.push_back(used);
    x = y = shelf = 0;
    used = IVec2(0);
  };
  // Tallest first, so that each shelf holds layers of similar heights (cropped layers vary a lot).
  std::vector<size_t> order(plan.layers.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return plan.layers[a].height > plan.layers[b].height; });
  for (const size_t i : order) {
    const int w = plan.layers[i].width + 2 * kAtlasPadding, h = plan.layers[i].height + 2 * kAtlasPadding;
    if (x > 0 && x + w > kAtlasSide) {  // next shelf
      y += shelf;
      x = shelf = 0;
    }
    if (y > 0 && y + h > kAtlasSide) close();  // next atlas
    plan.atlas_spots[i] = {uint32_t(plan.atlas_sizes.size()), x + kAtlasPadding, y + kAtlasPadding};
    x += w;
    shelf = std::max(shelf, h);
    used = glm::max(used, IVec2(x, y + shelf));
  }
  close();
}

namespace {

// K of the file comment (radians per metre). theta: half apex angle; d: capture eye distance.
double parallaxPerMetre(double theta, double d, double r, double gamma) {
  const auto first = [&](double D) {
    return std::sin(std::min(0.5 * kPi, gamma + theta + std::asin(std::min(1.0, r / D)))) / (D - r);
  };
  const auto rim = [&](double D) { return std::sqrt(std::max(0.0, D * D + d * d - 2.0 * D * d * std::cos(theta))); };
  double best = 0.0;
  double Da = d;
  for (int i = 0; i < 100000; ++i) {
    const double f = first(Da);
    if (f <= best) break;
    const double Db = Da * 1.01;
    best = std::max(best, std::min(f, rim(Db) / ((Da - r) * (Da - r))));
    Da = Db;
  }
  return best / std::cos(gamma);
}

struct FramePoint {
  double u, v, z;
};

std::array<FramePoint, 8> frameCorners(const Box3& box, const Vec3& apex, const DVec3& axis, const DVec3& right,
                                       const DVec3& up) {
  std::array<FramePoint, 8> out{};
  for (int i = 0; i < 8; ++i) {
    const DVec3 c((i & 1) ? box.hi.x : box.lo.x, (i & 2) ? box.hi.y : box.lo.y, (i & 4) ? box.hi.z : box.lo.z);
    const DVec3 x = c - DVec3(apex);
    out[size_t(i)] = {glm::dot(x, right), glm::dot(x, up), glm::dot(x, axis)};
  }
  return out;
}

// The rectangle, on the plane z = depth, of what E sees of the box between z = za and z = zb: the vertices of the
// box cut by the slab (corners inside it, edges crossing its planes) projected from E (a projective map of a convex
// polytope: its extremes are at vertices). Empty (lo > hi) when the box misses the slab.
struct PlaneRect {
  double u_lo = std::numeric_limits<double>::max(), v_lo = u_lo;
  double u_hi = std::numeric_limits<double>::lowest(), v_hi = u_hi;
  bool empty() const { return u_lo > u_hi; }
};

PlaneRect slabRect(const std::array<FramePoint, 8>& c, double za, double zb, double depth, double d) {
  PlaneRect r;
  const auto add = [&](double u, double v, double z) {
    const double scale = (d - depth) / (d - z);
    r.u_lo = std::min(r.u_lo, u * scale);
    r.u_hi = std::max(r.u_hi, u * scale);
    r.v_lo = std::min(r.v_lo, v * scale);
    r.v_hi = std::max(r.v_hi, v * scale);
  };
  for (const FramePoint& p : c)
    if (p.z >= za && p.z <= zb) add(p.u, p.v, p.z);
  for (int i = 0; i < 8; ++i)
    for (int bit = 1; bit < 8; bit <<= 1) {
      if (i & bit) continue;
      const FramePoint& a = c[size_t(i)];
      const FramePoint& b = c[size_t(i | bit)];
      for (double plane : {za, zb}) {
        if ((a.z - plane) * (b.z - plane) >= 0.0) continue;
        const double t = (plane - a.z) / (b.z - a.z);
        add(a.u + t * (b.u - a.u), a.v + t * (b.v - a.v), plane);
      }
    }
  return r;
}

// Half extents of slabRect around the axis.
Vec2 slabFootprint(const std::array<FramePoint, 8>& c, double za, double zb, double depth, double d) {
  const PlaneRect r = slabRect(c, za, zb, depth, d);
  if (r.empty()) return Vec2(0.0f);
  return Vec2(float(std::max(std::abs(r.u_lo), std::abs(r.u_hi))), float(std::max(std::abs(r.v_lo), std::abs(r.v_hi))));
}

// The texels of the tiles (kLayerTile, aligned to texel (0, 0)) of a layer image `width` x `height`, `s` metres a
// texel, that can hold data of a part seen in `r` or lie within a texel of it: a texel is captured where its centre
// lies in the part's projection, and a tile is drawn within a texel of a captured one (two texels of slack).
uint64_t partTileTexels(const PlaneRect& r, const LayerPlan& layer, double s) {
  if (r.empty()) return 0;
  const auto column = [&](double u) { return (u + double(layer.half_u)) / s; };
  const auto row = [&](double v) { return (double(layer.half_v) - v) / s; };
  const auto tileDown = [](double t, int n) { return std::clamp(int(std::floor(t)) - 2, 0, n) / kLayerTile * kLayerTile; };
  const auto tileUp = [](double t, int n) {
    const int i = std::clamp(int(std::ceil(t)) + 2, 0, n);
    return std::min(n, (i + kLayerTile - 1) / kLayerTile * kLayerTile);
  };
  const int x0 = tileDown(column(r.u_lo), layer.width), x1 = tileUp(column(r.u_hi), layer.width);
  const int y0 = tileDown(row(r.v_hi), layer.height), y1 = tileUp(row(r.v_lo), layer.height);
  return x1 > x0 && y1 > y0 ? uint64_t(x1 - x0) * uint64_t(y1 - y0) : 0;
}

// Margin by which a capture slab reaches past its nominal planes, so that a face lying exactly on a slab plane
// (axis-aligned boxes seen along an axis) is not lost to rounding at the near or far plane.
double slabMargin(const LayeredPlan& plan) { return 1e-4 * double(plan.shaft.min_distance) + 1e-3 * plan.spacing; }

}  // namespace

LayeredPlan planLayered(const Box3& box, const Shaft& shaft_in, const ErrorBound& bound,
                        const LayeredOptions& options, std::span<const Box3> parts) {
  if (box.empty() || !isFinite(box.lo) || !isFinite(box.hi))
    throw Error("layered impostor box", "empty or not finite (a cluster needs bounds)");
  for (size_t i = 0; i < parts.size(); ++i)
    if (parts[i].empty() || !isFinite(parts[i].lo) || !isFinite(parts[i].hi))
      throw Error("layered impostor part " + std::to_string(i), "empty or not finite");
  const Shaft shaft =
      Shaft::make(shaft_in.apex, shaft_in.axis, shaft_in.apex_angle, shaft_in.min_distance, "layered impostor shaft");
  bound.validate("layered impostor error bound");
  if (!(bound.pixels > 0.0)) throw Error("layered impostor error bound", "needs more than 0 pixels");
  if (!(options.texel_pixels > 0.0) || !std::isfinite(options.texel_pixels))
    throw Error("layered impostor options", "texel_pixels must be > 0");
  if (options.max_texture_size < 1 || options.max_texture_size > 16384)
    throw Error("layered impostor options", "max_texture_size must be 1..16384");
  if (options.max_layers < 1 || options.layer_count < 0 || options.layer_count > 4096)
    throw Error("layered impostor options", "max_layers must be >= 1 and layer_count 0..4096");
  if (options.dilate_texels < 0 || options.dilate_texels > 16)
    throw Error("layered impostor options", "dilate_texels must be 0..16");

  LayeredPlan plan;
  plan.shaft = shaft;
  plan.box = box;
  plan.id_textures = options.id_textures;
  plan.dilate_texels = options.dilate_texels;
  plan.solid_slices = options.solid_slices;
  const DVec3 axis(shaft.axis);
  const double d = shaft.min_distance;
  plan.capture_eye = Vec3(DVec3(shaft.apex) + d * axis);
  // The capture camera's frame exactly as glm::lookAt builds it (forward = -axis).
  plan.camera_up = std::abs(shaft.axis.z) < 0.9f ? Vec3(0.0f, 0.0f, 1.0f) : Vec3(0.0f, 1.0f, 0.0f);
  const DVec3 forward = -axis;
  const DVec3 right = glm::normalize(glm::cross(forward, DVec3(plan.camera_up)));
  const DVec3 up = glm::cross(right, forward);
  plan.right = Vec3(right);
  plan.up = Vec3(up);

  const std::array<FramePoint, 8> corners = frameCorners(box, shaft.apex, axis, right, up);
  double z_lo = std::numeric_limits<double>::max(), z_hi = std::numeric_limits<double>::lowest(), lateral = 0.0;
  for (const FramePoint& c : corners) {
    z_lo = std::min(z_lo, c.z);
    z_hi = std::max(z_hi, c.z);
    lateral = std::max(lateral, std::hypot(c.u, c.v));
  }
  plan.z_lo = float(z_lo);
  plan.z_hi = float(z_hi);
  if (!(d > z_hi))
    throw Error("layered impostor shaft", "minimum distance " + std::to_string(d) +
                                              " m does not clear the cluster (its near side is " +
                                              std::to_string(z_hi) + " m from the apex along the axis)");
  const double spread = (d - z_lo) / (d - z_hi);
  const double r = std::sqrt(lateral * spread * lateral * spread + std::max(z_lo * z_lo, z_hi * z_hi));
  if (!(d > r * (1.0 + 1e-6)))
    throw Error("layered impostor shaft", "minimum distance " + std::to_string(d) +
                                              " m does not clear the cluster (needs more than " + std::to_string(r) +
                                              " m)");
  plan.radius = r;
  const double gamma = std::atan(lateral / (d - z_hi));
  const double theta = 0.5 * double(shaft.apex_angle);
  plan.parallax_per_metre = parallaxPerMetre(theta, d, r, gamma);
  plan.bound_angle = bound.angle();

  const double depth_range = z_hi - z_lo;
  const double allowed = (options.bound_cracks ? 1.0 : 2.0) * plan.bound_angle;
  plan.max_spacing =
      plan.parallax_per_metre > 0.0 ? allowed / plan.parallax_per_metre : std::numeric_limits<double>::infinity();
  int count = 1;
  if (options.layer_count > 0) {
    count = options.layer_count;
  } else if (depth_range > 0.0) {
    const double needed = std::ceil(depth_range / plan.max_spacing);
    count = needed > double(options.max_layers) ? options.max_layers : std::max(1, int(needed));
    plan.layers_capped = needed > double(options.max_layers);
  }
  plan.spacing = depth_range / count;
  plan.error_angle = 0.5 * plan.parallax_per_metre * plan.spacing;

  // Texels: no larger than the wanted angle from the nearest viewpoint of each layer's quad. Every point drawn lies
  // within r of the apex, so every viewpoint (|V - apex| >= d) is at least d - r from it; and a viewpoint's axial
  // coordinate is at least d cos(theta) (within theta of the axis), so it is at least d cos(theta) - depth from the
  // plane z = depth. The layers on the far side of a deep cluster get coarser texels.
  const double wanted = bound.cornerPixelAngle() * std::min(options.texel_pixels, bound.pixels);
  const double near_gap = d - r;
  const double margin = slabMargin(plan);
  const double focal = bound.focalPixels();
  plan.layers.resize(size_t(count));
  for (int i = 0; i < count; ++i) {
    LayerPlan& layer = plan.layers[size_t(i)];
    const double za = z_lo + plan.spacing * i, zb = i + 1 == count ? z_hi : z_lo + plan.spacing * (i + 1);
    layer.z_lo = float(za);
    layer.z_hi = float(zb);
    layer.depth = float(0.5 * (za + zb));
    const Vec2 half = slabFootprint(corners, za - margin, zb + margin, layer.depth, d);
    const double gap = std::max(near_gap, d * std::cos(theta) - double(layer.depth));
    double s = wanted * gap;
    const double extent = 2.0 * std::max(half.x, half.y);
    if (extent / s > double(options.max_texture_size)) {
      s = extent / double(options.max_texture_size);
      plan.resolution_capped = true;
    }
    layer.width = std::clamp(int(std::ceil(2.0 * half.x / s)), 1, options.max_texture_size);
    layer.height = std::clamp(int(std::ceil(2.0 * half.y / s)), 1, options.max_texture_size);
    layer.half_u = float(0.5 * layer.width * s);
    layer.half_v = float(0.5 * layer.height * s);
    const double distance = d - layer.depth;
    layer.fov_y = float(2.0 * std::atan(layer.half_v / distance));
    plan.texel_angle = std::max(plan.texel_angle, s / gap);

    const uint64_t texels = uint64_t(layer.width) * uint64_t(layer.height);
    plan.texels += texels;
    plan.mesh_bytes += kLayerQuadBytes;
    const double pixels = 4.0 * layer.half_u * layer.half_v * focal * focal / (distance * distance);
    plan.fill_pixels += std::min(pixels, double(bound.width) * double(bound.height));
  }
  if (!parts.empty())
    for (size_t i = 0; i < plan.layers.size(); ++i) plan.layers[i].cover = plannedLayerCover(plan, i, parts);
  packAtlases(plan);
  for (const IVec2& a : plan.atlas_sizes)
    plan.texture_bytes += size_t(a.x) * size_t(a.y) * 4 * (options.id_textures ? 2 : 1);
  return plan;
}

float plannedLayerCover(const LayeredPlan& plan, size_t layer_index, std::span<const Box3> parts) {
  FF_CHECK(layer_index < plan.layers.size() && !plan.cropped);
  const LayerPlan& layer = plan.layers[layer_index];
  const DVec3 axis(plan.shaft.axis), right(plan.right), up(plan.up);
  const double d = plan.shaft.min_distance, margin = slabMargin(plan);
  const double texel = 2.0 * double(layer.half_u) / double(layer.width);
  uint64_t reached = 0;
  for (const Box3& part : parts) {
    const std::array<FramePoint, 8> corners = frameCorners(part, plan.shaft.apex, axis, right, up);
    reached += partTileTexels(slabRect(corners, layer.z_lo - margin, layer.z_hi + margin, layer.depth, d), layer, texel);
  }
  const double texels = double(layer.width) * double(layer.height);
  return std::min(1.0f, std::nextafter(float(double(reached) / texels), 2.0f));  // rounded up: a bound
}

size_t LayeredImpostor::cpuBytes() const {
  size_t bytes = 0;
  for (const Layer& layer : layers) bytes += 4 * (layer.color.pixelCount() + layer.ids.pixelCount());
  return bytes;
}

namespace {

// Spreads the colour of covered texels into uncovered ones (alpha stays 0), `rings` texels deep, so that bilinear
// filtering at the silhouette mixes neighbouring data colours and never the clear colour.
void dilateColors(image::ColorImage& color, int rings) {
  const int w = color.width(), h = color.height();
  std::vector<uint8_t> filled(color.pixelCount());
  for (size_t i = 0; i < filled.size(); ++i) filled[i] = color.pixels()[i].a > 0 ? 1 : 0;
  std::vector<uint8_t> next = filled;
  for (int ring = 0; ring < rings; ++ring) {
    bool any = false;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const size_t i = size_t(y) * size_t(w) + size_t(x);
        if (filled[i]) continue;
        int sum[3] = {0, 0, 0}, n = 0;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int nx = x + dx, ny = y + dy;
            if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
            const size_t j = size_t(ny) * size_t(w) + size_t(nx);
            if (!filled[j]) continue;
            for (int c = 0; c < 3; ++c) sum[c] += color.pixels()[j][c];
            ++n;
          }
        if (n == 0) continue;
        image::Rgba8& p = color.pixels()[i];
        for (int c = 0; c < 3; ++c) p[c] = uint8_t((sum[c] + n / 2) / n);
        next[i] = 1;
        any = true;
      }
    filled = next;
    if (!any) break;
  }
}

}  // namespace

LayeredImpostor captureLayered(gpu::Renderer& renderer, const gpu::GpuScene& scene,
                               std::span<const uint32_t> object_ids, const LayeredPlan& plan) {
  if (object_ids.empty()) throw Error("layered impostor objects", "the cluster lists no object");
  if (plan.layers.empty()) throw Error("layered impostor plan", "has no layers (make it with planLayered)");
  if (plan.cropped) throw Error("layered impostor plan", "is cropped: capture with the plan planLayered made");
  std::vector<gpu::DrawItem> items;
  try {
    scene.appendDrawItems(object_ids, items);
  } catch (const Error& e) {
    throw Error("layered impostor objects", e.what());
  }
  // Objects must lie in the box the plan was made for: outside it they would fall outside the slabs or images.
  const Vec3 diagonal = plan.box.extent();
  const float tolerance = 1e-4f * glm::length(diagonal) + 1e-4f;
  Box3 allowed = plan.box;
  allowed.lo -= Vec3(tolerance);
  allowed.hi += Vec3(tolerance);
  for (const gpu::DrawItem& item : items) {
    if (!item.mesh || item.mesh->indexCount() == 0) continue;
    const Box3 b = transformBox(item.mesh->bounds(), item.transform);
    if (!allowed.contains(b.lo) || !allowed.contains(b.hi))
      throw Error("layered impostor object " + std::to_string(item.object_id), "lies outside the cluster's box");
  }

  // Solid slices: every material double-sided (copies, one per distinct material, addresses kept stable).
  std::unordered_map<const gpu::GpuMaterial*, size_t> copy_of;
  std::vector<gpu::GpuMaterial> copies;
  if (plan.solid_slices) {
    copies.reserve(items.size());
    const gpu::GpuMaterial default_material;
    for (gpu::DrawItem& item : items) {
      const gpu::GpuMaterial* original = item.material ? item.material : &default_material;
      const auto [it, inserted] = copy_of.emplace(original, copies.size());
      if (inserted) {
        copies.push_back(*original);
        copies.back().double_sided = true;
      }
      item.material = &copies[it->second];
    }
  }

  Stopwatch total;
  LayeredImpostor out;
  out.plan = plan;
  const double d = plan.shaft.min_distance;
  const double margin = slabMargin(plan);
  for (const LayerPlan& lp : plan.layers) {
    Stopwatch timer;
    Camera camera;
    camera.eye = plan.capture_eye;
    camera.at = plan.shaft.apex;
    camera.up = plan.camera_up;
    camera.fov_y = lp.fov_y;
    camera.width = lp.width;
    camera.height = lp.height;
    camera.near_plane = float(std::max(d - lp.z_hi - margin, 1e-4 * d));
    camera.far_plane = float(d - lp.z_lo + margin);
    camera.validate("layered impostor capture camera");
    // As captureView (capture.h) does it, with the slab's planes and transparent black as the clear colour; clear
    // + draw rather than Renderer::render, whose GPU timer query cannot nest in a timed frame's.
    gpu::RenderTarget target(lp.width, lp.height);
    target.bind();
    target.clear(Vec4(0.0f));
    renderer.draw(camera, items, target);
    const image::DepthImage depth = target.readDepth();
    Layer layer;
    layer.color = target.readColor();
    for (size_t i = 0; i < layer.color.pixelCount(); ++i) {
      image::Rgba8& c = layer.color.pixels()[i];
      const bool covered = depth.pixels()[i] > 0.0f;  // reversed Z: 0 = nothing drawn
      c = covered ? image::Rgba8(c.r, c.g, c.b, 255) : image::Rgba8(0, 0, 0, 0);
      layer.data_texels += covered ? 1 : 0;
    }
    dilateColors(layer.color, plan.dilate_texels);
    if (plan.id_textures) layer.ids = target.readIds();
    layer.render_ms = timer.milliseconds();
    out.layers.push_back(std::move(layer));
  }
  out.capture_ms = total.milliseconds();
  return out;
}

}  // namespace farfield::impostor
