// Billboards (steed-ibr-impostors-lecture, part 2, "The simplest impostor: the billboard").
//
// Why several captured views and a validity angle: a single image turned to face every eye is right only along its
// capture direction; elsewhere it is the object rotated. The angle between the capture frame and the drawn frame
// (omega) bounds how far any point of the bounding sphere is misplaced, so errorAngle() can tell, per frame and per
// billboard, whether it keeps the error bound; the caller draws the geometry where it does not.
#include "farfield/impostor/billboard.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "farfield/core/error.h"
#include "farfield/impostor/capture.h"
#include "farfield/scene/mesh.h"

namespace farfield::impostor {
namespace {

BillboardFrame frameFacing(const Vec3& normal_in) {
  BillboardFrame f;
  f.normal = glm::normalize(normal_in);
  Vec3 r = glm::cross(-f.normal, Vec3(0, 0, 1));
  if (glm::length(r) < 1e-6f) r = Vec3(1, 0, 0);
  f.right = glm::normalize(r);
  f.up = glm::normalize(glm::cross(f.right, -f.normal));
  return f;
}

}  // namespace

const char* billboardKindName(BillboardKind kind) {
  return kind == BillboardKind::Spherical ? "spherical" : "cylindrical";
}

BillboardShape billboardShape(const Box3& bounds, const BillboardOptions& o) {
  if (bounds.empty() || !isFinite(bounds.lo) || !isFinite(bounds.hi))
    throw Error("billboard", "object bounds empty or not finite");
  if (o.views < 1 || o.views > 64) throw Error("billboard", "views outside 1..64");
  if (!(std::abs(o.elevation) <= 1.5)) throw Error("billboard", "elevation outside -1.5..1.5 rad");
  if (o.texels < 4 || o.texels > 2048) throw Error("billboard", "texels outside 4..2048");
  if (!(o.distance_factor > 1.0 && o.distance_factor < 1e6)) throw Error("billboard", "distance factor must be > 1");
  BillboardShape s;
  s.kind = o.kind;
  s.centre = bounds.center();
  s.radius = std::max(0.5f * glm::length(bounds.hi - bounds.lo), 1e-3f);
  s.capture_distance = float(o.distance_factor) * s.radius;
  const double D = s.capture_distance, r = s.radius;
  s.half_size = float(r * D / std::sqrt(D * D - r * r));
  const double elevation = o.kind == BillboardKind::Cylindrical ? 0.0 : o.elevation;
  for (int k = 0; k < o.views; ++k) {
    const double a = 2 * kPi * k / o.views;
    s.views.push_back(frameFacing(Vec3(std::cos(elevation) * std::cos(a), std::cos(elevation) * std::sin(a),
                                       std::sin(elevation))));
  }
  return s;
}

Camera BillboardShape::captureCamera(size_t view, int texels) const {
  const BillboardFrame& f = views.at(view);
  Camera c;
  c.eye = centre + capture_distance * f.normal;
  c.at = centre;
  c.up = f.up;
  c.fov_y = 2.0f * std::atan(half_size / capture_distance);
  c.width = c.height = texels;
  c.near_plane = std::max(capture_distance - 1.05f * radius, 1e-3f);
  c.far_plane = capture_distance + 1.05f * radius;
  return c;
}

BillboardFrame BillboardShape::orient(const Vec3& eye) const {
  Vec3 to_eye = eye - centre;
  if (kind == BillboardKind::Cylindrical) {
    to_eye.z = 0.0f;
    if (glm::length(to_eye) < 1e-6f) to_eye = Vec3(0, -1, 0);
    BillboardFrame f;
    f.normal = glm::normalize(to_eye);
    f.up = Vec3(0, 0, 1);
    f.right = glm::normalize(glm::cross(-f.normal, f.up));
    return f;
  }
  if (glm::length(to_eye) < 1e-6f) to_eye = Vec3(0, -1, 0);
  return frameFacing(to_eye);
}

size_t BillboardShape::nearestView(const Vec3& eye) const {
  const Vec3 n = orient(eye).normal;
  size_t best = 0;
  for (size_t k = 1; k < views.size(); ++k)
    if (glm::dot(views[k].normal, n) > glm::dot(views[best].normal, n)) best = k;
  return best;
}

std::array<Vec3, 4> BillboardShape::corners(const Vec3& eye) const {
  const BillboardFrame f = orient(eye);
  const Vec3 r = half_size * f.right, u = half_size * f.up;
  return {centre - r - u, centre + r - u, centre + r + u, centre - r + u};
}

double BillboardShape::errorAngle(const Vec3& eye) const {
  const double d = glm::length(DVec3(eye) - DVec3(centre));
  const double r = radius, D = capture_distance;
  if (!(d > r * 1.0001)) return kPi;
  const BillboardFrame drawn = orient(eye);
  const BillboardFrame& cap = views[nearestView(eye)];
  // Rotation taking the capture frame to the drawn one: M = F_drawn F_cap^T, trace = sum of dot products.
  const double trace = glm::dot(DVec3(drawn.right), DVec3(cap.right)) + glm::dot(DVec3(drawn.up), DVec3(cap.up)) +
                       glm::dot(DVec3(drawn.normal), DVec3(cap.normal));
  const double omega = std::acos(std::clamp((trace - 1.0) / 2.0, -1.0, 1.0));
  const DVec3 to_eye = (DVec3(eye) - DVec3(centre)) / d;
  const double tau = std::acos(std::clamp(glm::dot(DVec3(drawn.normal), to_eye), -1.0, 1.0));
  const double moved = 2.0 * r * std::sin(0.5 * omega) + r * std::sin(tau);
  const double depth = r * r * std::abs(D - d) / (d * (d - r) * (D - r));
  return std::min(kPi, std::atan(moved / (d - r)) + depth);
}

size_t Billboard::bytes() const {
  size_t b = 0;
  for (const image::ColorImage& im : images) b += size_t(im.width()) * size_t(im.height()) * 4;
  return b;
}

Billboard captureBillboard(gpu::Renderer& renderer, const gpu::GpuScene& scene, std::span<const uint32_t> ids,
                           const Box3& bounds, const BillboardOptions& options) {
  Billboard b;
  b.shape = billboardShape(bounds, options);
  b.texels = options.texels;
  CaptureOptions capture_options;
  capture_options.detect_seen_from_below = false;
  for (size_t k = 0; k < b.shape.views.size(); ++k) {
    ImpostorCapture cap = captureView(renderer, scene, ids, b.shape.captureCamera(k, b.texels), capture_options);
    image::ColorImage im = std::move(cap.color);
    // Transparent where no object was seen; the mean object colour under it, so bilinear filtering at the silhouette
    // blends towards the object, not the sky.
    double sum[3] = {0, 0, 0};
    size_t n = 0;
    for (int y = 0; y < im.height(); ++y)
      for (int x = 0; x < im.width(); ++x)
        if (cap.ids.at(x, y) != 0) {
          sum[0] += im.at(x, y).r, sum[1] += im.at(x, y).g, sum[2] += im.at(x, y).b;
          ++n;
        }
    const image::Rgba8 fill{uint8_t(n ? sum[0] / double(n) : 0), uint8_t(n ? sum[1] / double(n) : 0),
                            uint8_t(n ? sum[2] / double(n) : 0), 0};
    for (int y = 0; y < im.height(); ++y)
      for (int x = 0; x < im.width(); ++x) {
        if (cap.ids.at(x, y) == 0) im.at(x, y) = fill;
        else im.at(x, y).a = 255;
      }
    b.images.push_back(std::move(im));
  }
  return b;
}

BillboardBatch::BillboardBatch(std::span<const Billboard> billboards, int atlas_side) {
  if (billboards.empty()) throw Error("billboard batch", "no billboards");
  texels_ = billboards[0].texels;
  if (texels_ <= 0 || atlas_side < texels_) throw Error("billboard batch", "atlas smaller than a billboard image");
  tiles_per_side_ = atlas_side / texels_;
  tiles_per_atlas_ = tiles_per_side_ * tiles_per_side_;
  uint32_t tiles = 0;
  for (const Billboard& b : billboards) {
    if (b.texels != texels_ || b.images.size() != b.shape.views.size())
      throw Error("billboard batch", "billboards of different texel counts or without their images");
    view_base_.push_back(tiles);
    tiles += uint32_t(b.images.size());
    shapes_.push_back(b.shape);
  }
  const uint32_t atlas_count = (tiles + uint32_t(tiles_per_atlas_) - 1) / uint32_t(tiles_per_atlas_);
  for (uint32_t a = 0; a < atlas_count; ++a) {
    const uint32_t in_this = std::min<uint32_t>(uint32_t(tiles_per_atlas_), tiles - a * uint32_t(tiles_per_atlas_));
    const int rows = int((in_this + uint32_t(tiles_per_side_) - 1) / uint32_t(tiles_per_side_));
    image::ColorImage atlas(tiles_per_side_ * texels_, rows * texels_, image::Rgba8{0, 0, 0, 0});
    for (size_t i = 0; i < billboards.size(); ++i)
      for (size_t k = 0; k < billboards[i].images.size(); ++k) {
        const uint32_t tile = view_base_[i] + uint32_t(k);
        if (tile / uint32_t(tiles_per_atlas_) != a) continue;
        const int local = int(tile % uint32_t(tiles_per_atlas_));
        const int ox = (local % tiles_per_side_) * texels_, oy = (local / tiles_per_side_) * texels_;
        const image::ColorImage& im = billboards[i].images[k];
        for (int y = 0; y < texels_; ++y)
          for (int x = 0; x < texels_; ++x) atlas.at(ox + x, oy + y) = im.at(x, y);
      }
    auto tex = std::make_unique<gpu::Texture>(gpu::Texture::fromImage(atlas, false));
    tex->setClampToEdge();
    auto mat = std::make_unique<gpu::GpuMaterial>();
    mat->texture = tex.get();
    mat->unlit = true;
    mat->double_sided = true;
    atlases_.push_back(std::move(tex));
    materials_.push_back(std::move(mat));
  }
  meshes_.resize(atlases_.size());
}

size_t BillboardBatch::build(std::span<const uint32_t> which, const Vec3& eye, std::vector<gpu::DrawItem>& out,
                             uint32_t object_id) {
  std::vector<scene::Mesh> meshes(atlases_.size());
  for (const uint32_t i : which) {
    const BillboardShape& s = shapes_.at(i);
    const size_t k = s.nearestView(eye);
    const uint32_t tile = view_base_[i] + uint32_t(k);
    const uint32_t a = tile / uint32_t(tiles_per_atlas_);
    const int local = int(tile % uint32_t(tiles_per_atlas_));
    const float aw = float(atlases_[a]->width()), ah = float(atlases_[a]->height());
    const float u0 = float((local % tiles_per_side_) * texels_) / aw, u1 = u0 + float(texels_) / aw;
    const float v0 = float((local / tiles_per_side_) * texels_) / ah, v1 = v0 + float(texels_) / ah;
    scene::Mesh& m = meshes[a];
    const uint32_t first = uint32_t(m.positions.size());
    const std::array<Vec3, 4> c = s.corners(eye);
    const Vec3 n = s.orient(eye).normal;
    m.positions.insert(m.positions.end(), c.begin(), c.end());
    m.normals.insert(m.normals.end(), 4, n);
    m.uvs.insert(m.uvs.end(), {Vec2(u0, v1), Vec2(u1, v1), Vec2(u1, v0), Vec2(u0, v0)});
    m.indices.insert(m.indices.end(), {first, first + 1, first + 2, first, first + 2, first + 3});
  }
  size_t bytes = 0;
  for (size_t a = 0; a < meshes.size(); ++a) {
    if (meshes[a].indices.empty()) continue;
    meshes[a].computeBounds();
    bytes += meshes[a].byteSize();
    meshes_[a] = gpu::GpuMesh(meshes[a]);
    gpu::DrawItem item;
    item.mesh = &meshes_[a];
    item.material = materials_[a].get();
    item.object_id = object_id;
    out.push_back(item);
  }
  return bytes;
}

size_t BillboardBatch::textureBytes() const {
  size_t b = 0;
  for (const auto& t : atlases_) b += t->byteSize();
  return b;
}

}  // namespace farfield::impostor
