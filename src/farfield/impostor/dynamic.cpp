// Dynamic planar impostors (steed-ibr-impostors-lecture, part 2, "Impostors", "Choosing the best impostor plane";
// Shade et al. 1996).
//
// The quad is the capture frustum's cut by the best plane: its four corner rays met by the plane. With the plane
// tilted at most max_tilt from the view direction and the frustum only as wide as the bounding sphere, every ray
// meets it in front of the eye; if one did not (a huge tilt with a wide frustum), the plane falls back to the one
// facing the eye through the centre, which always works.
#include "farfield/impostor/dynamic.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "farfield/core/check.h"
#include "farfield/core/error.h"
#include "farfield/impostor/best_plane.h"
#include "farfield/scene/mesh.h"

namespace farfield::impostor {
namespace {

// Clip -> texture coordinates of a render target's colour texture: u = (ndc_x + 1) / 2, v = (ndc_y + 1) / 2 (GL
// textures of render targets have their row 0 at the bottom).
Mat4 targetTextureProjection(const Camera& camera) {
  Mat4 s(0.0f);
  s[0][0] = 0.5f;
  s[1][1] = 0.5f;
  s[3][0] = 0.5f;
  s[3][1] = 0.5f;
  s[3][3] = 1.0f;
  return s * camera.viewProjection();
}

bool cornersOnPlane(const Camera& cam, const ImpostorPlane& plane, std::array<Vec3, 4>& out) {
  const DVec3 eye(cam.eye), f = glm::normalize(DVec3(cam.at) - eye);
  const DVec3 r = glm::normalize(glm::cross(f, DVec3(cam.up))), u = glm::cross(r, f);
  const double t = std::tan(0.5 * double(cam.fov_y));
  const double sx[4] = {-1, 1, 1, -1}, sy[4] = {-1, -1, 1, 1};
  for (int i = 0; i < 4; ++i) {
    const DVec3 dir = f + t * sx[i] * r + t * sy[i] * u;
    const double denom = glm::dot(dir, plane.normal);
    if (std::abs(denom) < 1e-9) return false;
    const double s = glm::dot(plane.point - eye, plane.normal) / denom;
    if (!(s > 0.0)) return false;
    out[size_t(i)] = Vec3(eye + s * dir);
  }
  return true;
}

}  // namespace

const char* validityMetricName(ValidityMetric metric) {
  return metric == ValidityMetric::Shade ? "shade" : "schaufler";
}

ValidityMetric parseValidityMetric(const std::string& name, const std::string& where) {
  if (name == "shade") return ValidityMetric::Shade;
  if (name == "schaufler") return ValidityMetric::Schaufler;
  throw Error(where, "unknown validity metric '" + name + "' (shade, schaufler)");
}

PlanarImpostor::PlanarImpostor(gpu::Renderer& renderer, std::span<const gpu::DrawItem> items, const Box3& bounds,
                               std::span<const DVec3> samples, const Vec3& eye, double pixel_angle,
                               const PlanarImpostorOptions& o, const Vec3& fill) {
  if (samples.empty()) throw Error("planar impostor", "no sample points");
  if (!(o.texel_pixels > 0.0) || o.min_texels < 4 || o.max_texels > 4096 || o.min_texels > o.max_texels)
    throw Error("planar impostor", "bad options (texel_pixels > 0, 4 <= min_texels <= max_texels <= 4096)");
  if (!(pixel_angle > 0.0)) throw Error("planar impostor", "pixel angle must be > 0");
  centre_ = DVec3(bounds.center());
  radius_ = std::max(0.5 * glm::length(DVec3(bounds.hi) - DVec3(bounds.lo)), 1e-3);
  const double d = glm::length(DVec3(eye) - centre_);
  if (!(d > radius_ * 1.001)) throw Error("planar impostor", "the eye is inside the node's bounding sphere");
  samples_.assign(samples.begin(), samples.end());

  const double half = std::asin(std::min(1.0, radius_ * 1.02 / d));
  int side = int(std::ceil(2.0 * half / pixel_angle / o.texel_pixels));
  side = std::clamp((side + 3) / 4 * 4, o.min_texels, o.max_texels);
  camera_.eye = eye;
  camera_.at = Vec3(centre_);
  const Vec3 view = glm::normalize(camera_.at - camera_.eye);
  camera_.up = std::abs(view.z) > 0.99f ? Vec3(0, 1, 0) : Vec3(0, 0, 1);
  camera_.fov_y = float(2.0 * half);
  camera_.width = camera_.height = side;
  camera_.near_plane = float(std::max(d - radius_ * 1.05, 0.02));
  camera_.far_plane = float(d + radius_ * 1.05);

  plane_ = bestPlane(samples_, DVec3(eye), o.max_tilt).plane;
  if (o.plane_in_front) {
    double ahead = 0.0;
    for (const DVec3& p : samples_) ahead = std::max(ahead, glm::dot(p - plane_.point, plane_.normal));
    plane_.point += ahead * plane_.normal;
  }
  std::array<Vec3, 4> corners;
  if (!cornersOnPlane(camera_, plane_, corners)) {
    plane_ = ImpostorPlane{centre_, glm::normalize(DVec3(eye) - centre_)};
    FF_CHECK(cornersOnPlane(camera_, plane_, corners));
  }

  target_ = std::make_unique<gpu::RenderTarget>(side, side);
  Vec4 clear = renderer.light().sky_color;
  if (fill.r >= 0.0f && fill.g >= 0.0f && fill.b >= 0.0f) clear = Vec4(fill, 0.0f);
  clear.a = 0.0f;
  target_->clear(clear);
  if (!items.empty()) renderer.draw(camera_, items, *target_);

  scene::Mesh quad;
  quad.positions.assign(corners.begin(), corners.end());
  quad.normals.assign(4, Vec3(plane_.normal));
  quad.uvs = {Vec2(0, 1), Vec2(1, 1), Vec2(1, 0), Vec2(0, 0)};
  quad.indices = {0, 1, 2, 0, 2, 3};
  quad.computeBounds();
  mesh_ = gpu::GpuMesh(quad);
  material_ = std::make_unique<gpu::GpuMaterial>();
  material_->texture = &target_->colorTexture();
  material_->id_texture = &target_->idTexture();  // item buffers name the object of every image pixel
  material_->unlit = true;
  material_->double_sided = true;
  material_->projective_texture = true;
  material_->texture_projection = targetTextureProjection(camera_);
}

PlanarImpostor::PlanarImpostor(PlanarImpostor&&) noexcept = default;
PlanarImpostor& PlanarImpostor::operator=(PlanarImpostor&&) noexcept = default;
PlanarImpostor::~PlanarImpostor() = default;

double PlanarImpostor::error(ValidityMetric metric, const Vec3& eye) const {
  if (metric == ValidityMetric::Shade) return shadeError(samples_, plane_, DVec3(camera_.eye), DVec3(eye));
  return schauflerAngles(centre_, radius_, DVec3(camera_.eye), DVec3(eye)).worst();
}

double PlanarImpostor::shadeErrorOf(std::span<const DVec3> points, const Vec3& eye) const {
  return shadeError(points, plane_, DVec3(camera_.eye), DVec3(eye));
}

void PlanarImpostor::appendDrawItems(std::vector<gpu::DrawItem>& out, uint32_t object_id) const {
  gpu::DrawItem item;
  item.mesh = &mesh_;
  item.material = material_.get();
  item.object_id = object_id;
  out.push_back(item);
}

size_t PlanarImpostor::textureBytes() const {
  // Colour RGBA8, depth 32F, ids 32UI: the target's three attachments stay allocated with the image.
  return size_t(camera_.width) * size_t(camera_.height) * 12;
}

}  // namespace farfield::impostor
