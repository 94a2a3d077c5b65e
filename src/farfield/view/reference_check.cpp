#include "farfield/view/reference_check.h"

#include <algorithm>
#include <cmath>

#include "farfield/eval/bench.h"
#include "farfield/eval/parallax_error.h"
#include "farfield/image/metrics.h"

namespace farfield::view {

ReferenceCheck checkAgainstReference(gpu::Renderer& renderer, std::span<const gpu::DrawItem> reference_items,
                                     const Camera& camera, const gpu::RenderTarget& frame_target,
                                     gpu::RenderTarget& reference_target, size_t object_count, double bound_px) {
  ReferenceCheck check;
  const image::ColorImage frame = frame_target.readColor();
  const image::IdImage ids = frame_target.readIds();
  renderer.render(camera, reference_items, reference_target);
  const image::ColorImage reference = reference_target.readColor();
  const image::IdImage reference_ids = reference_target.readIds();

  const image::ImageMetrics metrics = image::compareImages(reference, frame);
  check.psnr_db = std::min(metrics.psnr_db, eval::kPsnrCapDb);
  check.ssim = metrics.ssim;
  check.bad_pixel_share = metrics.bad_pixel_share;
  check.heatmap = image::diffHeatmap(reference, frame);

  check.parallax_px = eval::frameParallaxPx(reference_ids, ids, object_count);
  check.parallax = std::isnan(check.parallax_px)
                       ? image::ColorImage(frame.width(), frame.height(), image::Rgba8(0, 0, 0, 255))
                       : eval::parallaxHeatmap(reference_ids, ids);
  check.bound_px = bound_px;
  check.over_bound = bound_px > 0.0 && check.parallax_px > bound_px;
  return check;
}

}  // namespace farfield::view
