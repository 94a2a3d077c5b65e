// Dynamic planar impostors (steed-ibr-impostors-lecture, part 2, "Impostors ... algorithm: select a subset of the
// model, create an image of the subset, replace the subset with the image"; Shade et al. 1996's hierarchical image
// cache, one image per node of the object hierarchy): an image of a node's objects rendered from the current eye
// into a texture of its own, drawn on the best plane for the node's sample points (impostor/best_plane.h), valid
// while the chosen metric (impostor/validity_metrics.h) keeps the error under the bound.
//
// The image is rendered on the GPU straight into the texture it is drawn with (no readback, no upload: the texels
// written are the update's traffic), and drawn with projective texturing from its capture camera, so from the
// capture eye it shows exactly the rendered image whatever the plane's orientation.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "farfield/core/bounds.h"
#include "farfield/core/camera.h"
#include "farfield/gpu/gpu_mesh.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/renderer.h"
#include "farfield/impostor/validity_metrics.h"

namespace farfield::impostor {

enum class ValidityMetric { Shade, Schaufler };
const char* validityMetricName(ValidityMetric metric);  // "shade", "schaufler"
// Throws farfield::Error naming `where` for another name.
ValidityMetric parseValidityMetric(const std::string& name, const std::string& where);

struct PlanarImpostorOptions {
  // Texel size in pixels of the viewer's frame at the capture distance (> 0). On the forest 0.5 (four times the
  // texels) gave 24.0 dB against 23.0 dB at 1.0 over 8 frames: the loss there is elsewhere (docs/BENCHMARKS.md).
  double texel_pixels = 1.0;
  int min_texels = 16;        // texture side bounds (4..4096)
  int max_texels = 512;
  double max_tilt = degToRad(60.0);  // the best plane's normal stays this close to the view direction
  // Move the best plane towards the eye until every sample lies behind it: nothing of the node pokes out in front
  // of its image, so geometry drawn around the image (the ground) cannot cut into it from within the node's own
  // bounds; the parallax grows with the distance from the plane, which Shade's metric sees and Schaufler's does not.
  bool plane_in_front = false;
};

class PlanarImpostor {
 public:
  // Renders `items` (a node's objects, whose world bounds are `bounds`) from `eye` looking at the bounds' centre,
  // the bounding sphere filling a square image of side 2 asin(r / d) / pixel_angle / texel_pixels texels (clamped),
  // with Renderer::draw into a target of its own cleared to transparent (allowed inside a timed frame). `samples`:
  // points of the objects (Shade's metric and the best plane use them; at least one). Throws farfield::Error for an
  // eye within the bounding sphere, no samples, or bad options. Needs a current context.
  // `fill`: the colour of the transparent texels (alpha 0) when its components are >= 0, else the sky colour. The
  // texture is filtered bilinearly, so texels at a silhouette mix it in; with small features (leaves) that shows,
  // and the objects' mean colour hides it (runtime/image_cache.cpp passes it).
  PlanarImpostor(gpu::Renderer& renderer, std::span<const gpu::DrawItem> items, const Box3& bounds,
                 std::span<const DVec3> samples, const Vec3& eye, double pixel_angle,
                 const PlanarImpostorOptions& options = {}, const Vec3& fill = Vec3(-1.0f));
  PlanarImpostor(PlanarImpostor&&) noexcept;
  PlanarImpostor& operator=(PlanarImpostor&&) noexcept;
  ~PlanarImpostor();

  // The metric's error angle (radians) seen from eye: Shade over the samples on this image's plane, or the worse
  // of Schaufler's two angles for the bounding sphere.
  double error(ValidityMetric metric, const Vec3& eye) const;
  // Shade's angle over other points (an audit with denser samples than the metric's).
  double shadeErrorOf(std::span<const DVec3> points, const Vec3& eye) const;
  void appendDrawItems(std::vector<gpu::DrawItem>& out, uint32_t object_id = 0) const;

  const Camera& camera() const { return camera_; }
  const ImpostorPlane& plane() const { return plane_; }
  const std::vector<DVec3>& samples() const { return samples_; }
  int texels() const { return camera_.width; }
  size_t textureBytes() const;  // colour texture (RGBA8) and the target's depth and id attachments
  size_t texelBytes() const { return size_t(camera_.width) * size_t(camera_.height) * 4; }  // colour written
  size_t meshBytes() const { return mesh_.byteSize(); }

 private:
  Camera camera_;
  DVec3 centre_{0.0};
  double radius_ = 0.0;
  ImpostorPlane plane_;
  std::vector<DVec3> samples_;
  std::unique_ptr<gpu::RenderTarget> target_;
  gpu::GpuMesh mesh_;
  std::unique_ptr<gpu::GpuMaterial> material_;
};

}  // namespace farfield::impostor
