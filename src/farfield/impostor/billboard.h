// Billboards (steed-ibr-impostors-lecture, part 2, "The simplest impostor: the billboard": an object image on a flat
// polygon that rotates to face the user; "nice trick to render trees"), camera-facing (spherical) and axis-aligned
// (cylindrical, turning about the vertical only), from captures of the object around it, with their validity under
// the error bound.
//
// Frame of a billboard: the object's bounding sphere (centre c, radius r). A view k is captured from the eye
// c + D * dir_k (D = capture_distance) looking at c, its image framing the sphere exactly at the plane through c
// facing the eye: the quad of half size h = r D / sqrt(D^2 - r^2). Drawn, the quad stands at c with the same half
// size, its normal towards the eye (spherical) or towards the eye's horizontal direction (cylindrical), textured
// with the view whose direction is nearest.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "farfield/core/bounds.h"
#include "farfield/core/camera.h"
#include "farfield/core/error_bound.h"
#include "farfield/gpu/gpu_mesh.h"
#include "farfield/gpu/renderer.h"
#include "farfield/gpu/texture.h"
#include "farfield/image/image.h"

namespace farfield::impostor {

enum class BillboardKind { Spherical, Cylindrical };
const char* billboardKindName(BillboardKind kind);

struct BillboardOptions {
  BillboardKind kind = BillboardKind::Cylindrical;
  int views = 8;                // capture azimuths, evenly spaced, 1..64
  double elevation = 0.0;       // capture elevation, radians (-1.5..1.5); cylindrical billboards use 0 whatever
  int texels = 64;              // image side, 4..2048
  double distance_factor = 8.0; // D = distance_factor * r, > 1
};

struct BillboardFrame {
  Vec3 normal{0, -1, 0};  // unit, towards the eye the view is (was) seen from
  Vec3 right{1, 0, 0};    // unit, the image's x axis (world)
  Vec3 up{0, 0, 1};       // unit, the image's up axis (world)
};

// Geometry of a billboard without its images (pure arithmetic; what validity needs).
struct BillboardShape {
  BillboardKind kind = BillboardKind::Cylindrical;
  Vec3 centre{0.0f};
  float radius = 0.0f;
  float capture_distance = 0.0f;
  float half_size = 0.0f;
  std::vector<BillboardFrame> views;  // the capture frames

  // Camera of view k (square, texels a side).
  Camera captureCamera(size_t view, int texels) const;
  // The frame the quad takes for an eye (spherical: normal towards the eye; cylindrical: towards its horizontal
  // direction, up = +z) and the view it shows (nearest capture direction to the quad's normal).
  BillboardFrame orient(const Vec3& eye) const;
  size_t nearestView(const Vec3& eye) const;
  // The quad's corners for an eye: lower-left, lower-right, upper-right, upper-left (as the image's rows go up).
  std::array<Vec3, 4> corners(const Vec3& eye) const;
  // Upper bound (radians) of the angle between a point of the object and where the billboard shows it, seen from
  // eye: the image is the object seen along view k, turned rigidly into the drawn frame (rotation by omega: points
  // move at most 2 r sin(omega / 2)), tilted by the angle tau between the drawn normal and the eye (at most
  // r sin(tau) more), and flat where the object has depth (the capture and the eye see its depth +-r from
  // different distances D and d: r^2 |D - d| / (d (d - r)(D - r))). pi when the eye is within the sphere.
  double errorAngle(const Vec3& eye) const;
};

// The shape for an object with world bounds `bounds` (its bounding sphere). Throws farfield::Error for an empty or
// non-finite box or options out of range.
BillboardShape billboardShape(const Box3& bounds, const BillboardOptions& options);

struct Billboard {
  BillboardShape shape;
  int texels = 0;
  std::vector<image::ColorImage> images;  // per view: RGBA, alpha 0 where no object was seen
  size_t bytes() const;
};

// Captures the objects `ids` (1-based) of the scene from each view of billboardShape(bounds, options). Needs a
// current context. Throws farfield::Error as billboardShape and captureView do.
Billboard captureBillboard(gpu::Renderer& renderer, const gpu::GpuScene& scene, std::span<const uint32_t> ids,
                           const Box3& bounds, const BillboardOptions& options);

// Many billboards on the GPU: their view images packed into square atlases (tiles of equal size), and per frame one
// mesh of the quads drawn, built on the CPU and uploaded (its bytes are the frame's bus traffic), one draw item per
// atlas: unlit, double-sided, alpha-tested. Needs a current context.
class BillboardBatch {
 public:
  // All billboards must have the same texel count. Throws farfield::Error otherwise or for none.
  explicit BillboardBatch(std::span<const Billboard> billboards, int atlas_side = 4096);
  BillboardBatch(BillboardBatch&&) noexcept = default;
  BillboardBatch& operator=(BillboardBatch&&) noexcept = default;

  // Rebuilds the frame's mesh for the listed billboards (indices into the constructor's span), oriented for eye,
  // and appends one draw item per atlas used, with object_id. Returns the bytes uploaded (vertices and indices).
  size_t build(std::span<const uint32_t> which, const Vec3& eye, std::vector<gpu::DrawItem>& out,
               uint32_t object_id = 0);
  size_t textureBytes() const;
  size_t size() const { return shapes_.size(); }
  const BillboardShape& shape(size_t i) const { return shapes_[i]; }

 private:
  std::vector<BillboardShape> shapes_;
  int texels_ = 0, tiles_per_side_ = 0, tiles_per_atlas_ = 0;
  std::vector<std::unique_ptr<gpu::Texture>> atlases_;
  std::vector<std::unique_ptr<gpu::GpuMaterial>> materials_;
  std::vector<gpu::GpuMesh> meshes_;  // per atlas, this frame's quads
  std::vector<uint32_t> view_base_;   // per billboard: index of its first view's tile
};

}  // namespace farfield::impostor
