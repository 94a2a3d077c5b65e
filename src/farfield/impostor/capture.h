// Capture of the distant model for an impostor (Sillion et al. 1997, section 4.2, steps 1-2): colour, window depth
// and object ids rendered with the gpu module from the impostor's creation camera.
#pragma once

#include <cstdint>
#include <span>

#include "farfield/core/camera.h"
#include "farfield/gpu/renderer.h"
#include "farfield/image/image.h"

namespace farfield::impostor {

struct CaptureOptions {
  // Mark "seen from below" pixels (see contour.h): one more render of the same objects with every material
  // double-sided; where it is nearer than the normal (back-face culled) render, the first surface along the ray
  // is a back face (the underside of a ground element, the inside of an open shell). Those pixels get
  // kSeenFromBelowColor, which the contour extraction treats as background. (That render samples no textures:
  // cut-out texels of single-sided materials count as solid there, see capture.cpp.)
  bool detect_seen_from_below = true;
};

struct ImpostorCapture {
  image::ColorImage color;   // lit colour; sky where nothing was drawn; kSeenFromBelowColor where seen from below
  image::DepthImage depth;   // window depth, reversed Z (0 = background)
  image::IdImage ids;        // object ids (0 = background)
  Camera camera;             // the creation camera (its width x height is the image size)
  size_t data_pixels = 0;    // pixels that are impostor data (isImpostorData)
  size_t seen_from_below_pixels = 0;
  double render_ms = 0.0;    // wall time of the render pass(es) and readbacks
};

// Renders the listed objects of the scene (ids 1-based; an EMPTY list draws nothing, unlike
// GpuScene::appendDrawItems, because an empty distant model must give an empty impostor) from `camera` into a
// camera.width x camera.height target. Needs a current context. Throws farfield::Error for a bad camera or an id
// out of range.
ImpostorCapture captureView(gpu::Renderer& renderer, const gpu::GpuScene& scene,
                            std::span<const uint32_t> object_ids, const Camera& camera,
                            const CaptureOptions& options = {});
// The same with a renderer made for this call (compiles the shaders: keep a Renderer when capturing many views).
ImpostorCapture captureView(const gpu::GpuScene& scene, std::span<const uint32_t> object_ids, const Camera& camera,
                            const CaptureOptions& options = {});

}  // namespace farfield::impostor
