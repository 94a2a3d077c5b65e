// Dynamically updated regular-grid impostors (Decoret et al. 1999, section 5.5, "Selective dynamic updates of
// impostors"): a layer of objects is re-rendered from the viewer's current position inside the frame, its depth kept
// with eight bits only, sub-sampled into a regular grid mesh and drawn in place of the layer's pre-computed mesh.
// The paper: "We store the textures of our meshes with a limited depth information of eight bits. For regular-grid
// impostors, this depth information is sub-sampled and converted into an efficient mesh ... The resulting meshed
// impostor therefore makes no attempt to capture important depth disparities, under the assumption that it will be
// short-lived." Updates are ordered by Schaufler's error angle (errorAngle below); how long one stays valid is
// what covers() and errorAngle() tell a scheduler.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "farfield/core/bounds.h"
#include "farfield/core/camera.h"
#include "farfield/gpu/renderer.h"
#include "farfield/image/image.h"
#include "farfield/impostor/drawable.h"

namespace farfield::runtime {

struct DynamicImpostorOptions {
  // The capture camera's field of view is the viewer's times this, tan-wise (tan(fov'/2) = margin * tan(fov/2)),
  // so that turning the head a little keeps the impostor valid (covers()). >= 1.
  float fov_margin = 1.25f;
  // Capture width = height in pixels; 0 = max(viewer width, height) times fov_margin, rounded up to a multiple of 8,
  // which keeps the viewer's angular resolution at the centre of the view.
  int resolution = 0;
  // Mesh grid spacing in pixels: the sub-sampling of the depth (impostor::GridMeshOptions::grid_spacing_px). >= 1.
  int grid_px = 8;
  // Depth quantisation, bits (1..16); 8 as in the paper.
  int depth_bits = 8;
  // Read the capture's ids back and draw them as an id texture, so item buffers show the object of every pixel as
  // with the baked layers; otherwise the whole impostor draws with appendDrawItems' id.
  bool object_ids = false;
};

// Schaufler's error angle (radians) of an image of the objects within `bounds` captured from `capture_eye`, seen
// from `eye`: the largest angle, seen from `eye`, between two points of the bounds that lie on one ray of the capture
// eye (they were one pixel in the image; the image cannot show their parallax, so this angle is what it gets wrong).
//
// Closed form: with s = |eye - capture_eye| and d_min / d_max the nearest / farthest distances from capture_eye to the
// bounds, two points on one capture ray at distances d1 < d2 subtend at most
//     s * (1 / (d_min - s) - 1 / (d_max - s))
// from the new eye. For s << d_min this is Schaufler's s * (1/d_min - 1/d_max); the "- s" makes it a true upper bound
// for any motion (the angle is the integral over the segment of s sin(phi) / r^2 with r, the distance from the new
// eye, at least d - s), where the first-order form underestimates when the viewer moves towards the objects. Returns
// 0 at the capture eye itself and for empty bounds; pi (the largest angle) when s >= d_min, which includes every
// moved eye when capture_eye is inside the bounds. Capped at pi.
double errorAngle(const Vec3& capture_eye, const Vec3& eye, const Box3& bounds);

// The depth of a capture with `bits` bits, as the paper stores it: window depth quantised uniformly between the
// farthest and the nearest data depth of the image (pixels with window depth > 0; 0 is background). Reversed-Z window
// depth is an affine function of inverse distance (1/d), so this is uniform quantisation in inverse depth, which is
// what parallax (and the error angle) is linear in: each code spans the same angular error for a moving viewer.
struct QuantizedDepth {
  image::DepthImage window_depth;  // dequantised window depth; background pixels stay exactly 0
  std::vector<uint16_t> codes;     // per pixel, 0 .. 2^bits - 1 (0 also for background, see window_depth)
  float window_near = 0.0f;        // window depth of code 2^bits - 1 (the nearest data depth)
  float window_far = 0.0f;         // window depth of code 0 (the farthest data depth)
  float near_m = 0.0f;             // the same bounds as linear depth, metres (0 and 0 when there is no data)
  float far_m = 0.0f;
  size_t data_pixels = 0;
};
// Throws farfield::Error for bits outside 1..16 or a window depth outside [0, 1]. Needs the capture camera for the
// linear bounds only.
QuantizedDepth quantizeDepth(const image::DepthImage& window_depth, const Camera& camera, int bits);

class DynamicImpostor {
 public:
  // The update: renders the items (one layer's objects, from gpu::GpuScene::appendDrawItems) from
  // captureCamera(viewer, options) into a render target of its own with Renderer::draw, after clearing it (colour:
  // the renderer's sky colour with alpha 0, ids 0, depth 0 = background); reads back colour and depth (not the ids:
  // the layer is drawn with one object id, see appendDrawItems); quantises the depth (quantizeDepth) and builds the
  // regular-grid mesh from the dequantised depth (impostor::buildGridMesh, grid_spacing_px = grid_px) and uploads it
  // as an impostor::GpuImpostor with projective texturing (exact from the capture eye whatever the quantised depths).
  //
  // Meant to run inside a timed frame: it never calls Renderer::render (which waits for the GPU and starts a
  // GL_TIME_ELAPSED query that cannot nest in the frame's) nor waits for the GPU other than through the readback,
  // which must wait for the capture. The caller's next Renderer::draw binds its own target again. There is no
  // "seen from below" pass (impostor/capture.h): a short-lived impostor does not pay a second render for it.
  //
  // Cost measured on llvmpipe (2 busy cores), 512 x 512 viewer, 640 x 640 capture: 23-25 ms for a few boxes against
  // the sky, ~20 ms of it impostor::buildGridMesh (its per-triangle pixel scan and the nearest-data search for grid
  // vertices on background); ~30 ms for a street view of a city, mostly the capture render and readback.
  //
  // `bounds`: the world bounds of the items (for errorAngle and covers()). Needs a current context. Throws
  // farfield::Error for bad options or an unusable viewer camera. An update of items that cover no pixel gives an
  // empty impostor (draws nothing).
  DynamicImpostor(gpu::Renderer& renderer, std::span<const gpu::DrawItem> items, const Camera& viewer,
                  const Box3& bounds, const DynamicImpostorOptions& options = {});
  DynamicImpostor(DynamicImpostor&&) noexcept;
  DynamicImpostor& operator=(DynamicImpostor&&) noexcept;
  ~DynamicImpostor();

  // The viewer's eye, look-at point, up and planes; a square image of options.resolution (or the default) pixels
  // whose field of view contains the viewer's widened by fov_margin in both directions. Throws farfield::Error for
  // fov_margin < 1 or not finite, a resolution outside 0..16384, or a margin that widens the view to 180 degrees.
  static Camera captureCamera(const Camera& viewer, const DynamicImpostorOptions& options);

  // True when the viewer's frustum, over the depths where the bounds lie, is within the capture frustum: points along
  // the viewer's four corner rays (and its view direction), at the nearest and farthest view depth of the bounds
  // (clamped to the viewer's near and far planes), project inside the capture image and in front of the capture eye.
  // Both are convex, so the corners decide. A viewer that has also moved is judged with the same points; how wrong
  // the parallax then is, is errorAngle()'s question.
  bool covers(const Camera& viewer) const;
  // errorAngle(camera().eye, eye, bounds)
  double errorAngle(const Vec3& eye) const;

  // Draw items of the mesh, all with `object_id` (the same id for the whole layer).
  void appendDrawItems(std::vector<gpu::DrawItem>& out, uint32_t object_id) const;

  uint64_t triangleCount() const;
  double updateMs() const { return update_ms_; }  // wall time of the whole update (render, readback, mesh, upload)
  const Camera& camera() const { return camera_; }  // the capture camera
  const Box3& bounds() const { return bounds_; }
  bool empty() const;
  size_t gpuBytes() const;  // texture and mesh
  size_t dataPixels() const { return data_pixels_; }  // pixels of the capture covered by the layer
  // Quantisation bounds (linear depth from the capture eye, metres): the nearest and farthest data depth.
  double depthNear() const { return depth_near_; }
  double depthFar() const { return depth_far_; }

 private:
  Camera camera_;
  Box3 bounds_;
  std::unique_ptr<impostor::GpuImpostor> impostor_;
  double update_ms_ = 0.0;
  size_t data_pixels_ = 0;
  double depth_near_ = 0.0;
  double depth_far_ = 0.0;
};

}  // namespace farfield::runtime
