// Dynamic regular-grid impostor updates (Decoret et al. 1999, section 5.5) with Schaufler's error angle.
//
// Why the update works the way it does:
// - Same eye as the viewer, wider field of view: the image is exact for the viewer at the moment of the update
//   (projective texturing reproduces every captured texel along its own ray), and the margin lets the view turn a
//   little before the impostor's edge shows. Moving away from the capture eye is what degrades it; the error angle
//   measures that, and the scheduler re-captures the layers with the largest angle first.
// - Eight-bit depth: the paper keeps the textures with eight bits of depth to make updates cheap. Quantising in
//   inverse depth (uniform in reversed-Z window depth, which is affine in 1/d) spends the codes where parallax is:
//   a code step is the same parallax angle for a moving viewer whatever the distance, and near layers get fine steps.
// - A regular grid: meshing a grid costs a fixed, small time per image (no contour tracing or triangulation), which
//   is what an update inside a frame budget needs. The grid ignores depth discontinuities; the paper accepts this
//   "under the assumption that it will be short-lived".
#include "farfield/runtime/dynamic_impostor.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "farfield/core/error.h"
#include "farfield/core/timer.h"
#include "farfield/gpu/render_target.h"
#include "farfield/impostor/grid_mesh.h"

namespace farfield::runtime {

double errorAngle(const Vec3& capture_eye, const Vec3& eye, const Box3& bounds) {
  if (bounds.empty()) return 0.0;
  const DVec3 c(capture_eye);
  const double s = glm::length(DVec3(eye) - c);
  if (s == 0.0) return 0.0;  // the image is exact from where it was taken
  // Nearest point of the box (0 inside) and farthest corner.
  const DVec3 lo(bounds.lo), hi(bounds.hi);
  const double d_min = glm::length(glm::max(glm::max(lo - c, c - hi), DVec3(0.0)));
  const double d_max = glm::length(glm::max(glm::abs(lo - c), glm::abs(hi - c)));
  // Two points of one capture ray at distances d1 < d2 subtend, from an eye moved by s at angle phi to the ray,
  // the integral over d in [d1, d2] of s sin(phi) / r(d)^2, where r(d) >= d - s is the distance from the new eye.
  // Bounding sin(phi) by 1 and r by d - s, and widening [d1, d2] to [d_min, d_max], gives the closed form.
  if (s >= d_min) return kPi;
  return std::min(kPi, s * (1.0 / (d_min - s) - 1.0 / (d_max - s)));
}

QuantizedDepth quantizeDepth(const image::DepthImage& window_depth, const Camera& camera, int bits) {
  if (bits < 1 || bits > 16)
    throw Error("depth quantisation", "bits must be 1..16, got " + std::to_string(bits));
  QuantizedDepth out;
  out.window_depth = image::DepthImage(window_depth.width(), window_depth.height(), 0.0f);
  out.codes.assign(window_depth.pixelCount(), 0);
  float z_far = std::numeric_limits<float>::max(), z_near = 0.0f;
  for (float z : window_depth.pixels()) {
    if (!(z >= 0.0f && z <= 1.0f))
      throw Error("depth quantisation", "window depth " + std::to_string(z) + " is not in [0, 1]");
    if (z > 0.0f) {
      z_far = std::min(z_far, z);
      z_near = std::max(z_near, z);
      ++out.data_pixels;
    }
  }
  if (out.data_pixels == 0) return out;
  out.window_far = z_far;
  out.window_near = z_near;
  out.near_m = camera.linearDepth(z_near);
  out.far_m = camera.linearDepth(z_far);
  const uint32_t levels = (1u << bits) - 1u;
  const double range = double(z_near) - double(z_far);
  const double to_code = range > 0.0 ? double(levels) / range : 0.0;
  const double to_depth = double(range) / double(levels);
  const float* in = window_depth.data();
  float* dequantised = out.window_depth.data();
  for (size_t i = 0; i < window_depth.pixelCount(); ++i) {
    const float z = in[i];
    if (z <= 0.0f) continue;  // background stays 0
    // Round to the nearest code; z is within [z_far, z_near], so the code is within [0, levels].
    const uint32_t code = std::min(levels, uint32_t((double(z) - double(z_far)) * to_code + 0.5));
    out.codes[i] = uint16_t(code);
    // Dequantised into [z_far, z_near]: never 0, so a data pixel stays data.
    dequantised[i] = std::clamp(float(double(z_far) + double(code) * to_depth), z_far, z_near);
  }
  return out;
}

Camera DynamicImpostor::captureCamera(const Camera& viewer, const DynamicImpostorOptions& options) {
  viewer.validate("dynamic impostor viewer");
  if (!(std::isfinite(options.fov_margin) && options.fov_margin >= 1.0f))
    throw Error("dynamic impostor", "fov_margin must be a finite number >= 1, got " +
                                        std::to_string(options.fov_margin));
  if (options.resolution < 0 || options.resolution > 16384)
    throw Error("dynamic impostor", "resolution must be 0 (automatic) or 1..16384, got " +
                                        std::to_string(options.resolution));
  // A square image whose half-angle tangent is the margin times the larger of the viewer's two: it contains the
  // viewer's frustum widened by the margin in both directions.
  const double tan_y = std::tan(0.5 * double(viewer.fov_y));
  const double tan_half = double(options.fov_margin) * std::max(tan_y, tan_y * double(viewer.aspect()));
  Camera c = viewer;
  c.fov_y = float(2.0 * std::atan(tan_half));
  if (!(c.fov_y < float(kPi) * 0.999f))
    throw Error("dynamic impostor", "fov_margin " + std::to_string(options.fov_margin) +
                                        " widens the view to 180 degrees");
  int size = options.resolution;
  if (size == 0) {
    // Square pixels: the viewer has max(w, h) / (2 max(tan)) pixels per unit of tangent; keep that density.
    size = int(std::ceil(double(std::max(viewer.width, viewer.height)) * double(options.fov_margin) / 8.0)) * 8;
    if (size > 16384)
      throw Error("dynamic impostor", "automatic resolution " + std::to_string(size) + " exceeds 16384 pixels");
  }
  c.width = c.height = size;
  c.validate("dynamic impostor capture camera");
  return c;
}

DynamicImpostor::DynamicImpostor(gpu::Renderer& renderer, std::span<const gpu::DrawItem> items, const Camera& viewer,
                                 const Box3& bounds, const DynamicImpostorOptions& options)
    : bounds_(bounds) {
  Stopwatch clock;
  if (options.grid_px < 1)
    throw Error("dynamic impostor", "grid_px must be at least 1, got " + std::to_string(options.grid_px));
  if (options.depth_bits < 1 || options.depth_bits > 16)
    throw Error("dynamic impostor", "depth_bits must be 1..16, got " + std::to_string(options.depth_bits));
  camera_ = captureCamera(viewer, options);

  // Capture with draw() on a target of our own, cleared to transparent sky: inside a frame the renderer's timer
  // query is running, so Renderer::render is not allowed here.
  gpu::RenderTarget target(camera_.width, camera_.height);
  Vec4 clear = renderer.light().sky_color;
  clear.a = 0.0f;
  target.clear(clear);
  if (!items.empty()) renderer.draw(camera_, items, target);
  // The readback is the one wait for the GPU. The id image only when the triangles are to carry object ids.
  const image::ColorImage color = target.readColor();
  const image::DepthImage depth = target.readDepth();
  const image::IdImage ids = options.object_ids ? target.readIds() : image::IdImage();

  const QuantizedDepth quantized = quantizeDepth(depth, camera_, options.depth_bits);
  data_pixels_ = quantized.data_pixels;
  depth_near_ = quantized.near_m;
  depth_far_ = quantized.far_m;
  impostor::GridMeshOptions grid;
  grid.grid_spacing_px = double(options.grid_px);
  const impostor::DepthMeshImpostor mesh = impostor::buildGridMesh(color, quantized.window_depth, camera_, grid,
                                                                   options.object_ids ? &ids : nullptr);
  impostor::GpuImpostorOptions upload;
  upload.projective_texture = true;
  upload.id_texture = options.object_ids;
  impostor_ = std::make_unique<impostor::GpuImpostor>(mesh, upload);
  update_ms_ = clock.milliseconds();
}

DynamicImpostor::DynamicImpostor(DynamicImpostor&&) noexcept = default;
DynamicImpostor& DynamicImpostor::operator=(DynamicImpostor&&) noexcept = default;
DynamicImpostor::~DynamicImpostor() = default;

bool DynamicImpostor::covers(const Camera& viewer) const {
  viewer.validate("dynamic impostor viewer");
  // The viewer's orthonormal frame, as glm::lookAt builds it.
  const Vec3 f = viewer.forward();
  const Vec3 right = glm::normalize(glm::cross(f, viewer.up));
  const Vec3 up = glm::cross(right, f);
  const float tan_y = std::tan(0.5f * viewer.fov_y), tan_x = tan_y * viewer.aspect();
  // View depths of the bounds (where the impostor can be seen), clamped to the viewer's planes.
  float d_lo = viewer.near_plane, d_hi = viewer.near_plane;
  if (!bounds_.empty()) {
    d_lo = std::numeric_limits<float>::max();
    d_hi = std::numeric_limits<float>::lowest();
    for (int i = 0; i < 8; ++i) {
      const Vec3 corner((i & 1) ? bounds_.hi.x : bounds_.lo.x, (i & 2) ? bounds_.hi.y : bounds_.lo.y,
                        (i & 4) ? bounds_.hi.z : bounds_.lo.z);
      const float d = glm::dot(corner - viewer.eye, f);
      d_lo = std::min(d_lo, d);
      d_hi = std::max(d_hi, d);
    }
    d_lo = std::clamp(d_lo, viewer.near_plane, viewer.far_plane);
    d_hi = std::clamp(d_hi, viewer.near_plane, viewer.far_plane);
  }
  // A hair of tolerance: the projection of an exact edge ray lands on the edge give or take rounding.
  const float tol_x = 1e-4f * float(camera_.width), tol_y = 1e-4f * float(camera_.height);
  const std::array<Vec2, 5> rays{Vec2(-1, -1), Vec2(1, -1), Vec2(-1, 1), Vec2(1, 1), Vec2(0, 0)};
  for (float d : {d_lo, d_hi})
    for (const Vec2& r : rays) {
      const Vec3 p = viewer.eye + d * (f + r.x * tan_x * right + r.y * tan_y * up);
      float w = 0.0f;
      const Vec3 q = camera_.project(p, &w);
      if (!(w > 0.0f)) return false;
      if (q.x < -tol_x || q.x > float(camera_.width) + tol_x || q.y < -tol_y || q.y > float(camera_.height) + tol_y)
        return false;
    }
  return true;
}

double DynamicImpostor::errorAngle(const Vec3& eye) const { return runtime::errorAngle(camera_.eye, eye, bounds_); }

void DynamicImpostor::appendDrawItems(std::vector<gpu::DrawItem>& out, uint32_t object_id) const {
  if (impostor_) impostor_->appendDrawItems(out, object_id);
}

uint64_t DynamicImpostor::triangleCount() const { return impostor_ ? impostor_->triangleCount() : 0; }
bool DynamicImpostor::empty() const { return !impostor_ || impostor_->empty(); }
size_t DynamicImpostor::gpuBytes() const { return impostor_ ? impostor_->gpuBytes() : 0; }

}  // namespace farfield::runtime
