// The reference check of the frame on screen (the viewer's R key), as `farfield bench --reference` measures every
// frame: the full-geometry render of the same camera, the image error against it (PSNR, SSIM, pixels off by more
// than 8/255) with its heat map, and the parallax error from object ids (eval/parallax_error.h: the 99th percentile
// over the object pixels, skipping objects absent from the frame, as bench does) with its map.
#pragma once

#include <cstddef>
#include <span>

#include "farfield/core/camera.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/renderer.h"
#include "farfield/image/image.h"

namespace farfield::view {

struct ReferenceCheck {
  size_t frame = 0;            // the viewer's frame number
  double psnr_db = 0.0;        // capped at 99 for identical frames
  double ssim = 0.0;
  double bad_pixel_share = 0.0;
  double parallax_px = 0.0;    // NaN when the frame shows ids that are not scene objects
  double bound_px = 0.0;       // the bound it was checked against, 0 = none
  bool over_bound = false;     // parallax_px > bound_px > 0
  image::ColorImage heatmap;   // diffHeatmap(reference, frame)
  image::ColorImage parallax;  // per-pixel parallax, black = right, red to yellow = 1 to 32+ px
};

// Renders reference_items (all of the scene's items) with the camera into reference_target and compares the frame
// now in frame_target (the mode's untinted frame; same size) with it.
ReferenceCheck checkAgainstReference(gpu::Renderer& renderer, std::span<const gpu::DrawItem> reference_items,
                                     const Camera& camera, const gpu::RenderTarget& frame_target,
                                     gpu::RenderTarget& reference_target, size_t object_count, double bound_px);

}  // namespace farfield::view
