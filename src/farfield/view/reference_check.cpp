#include "farfield/view/reference_check.h"

#include <algorithm>
#include <cmath>
#include <limits>

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
  check.psnr_db = std::min(metrics.psnr_db, 99.0);
  check.ssim = metrics.ssim;
  check.bad_pixel_share = metrics.bad_pixel_share;
  check.heatmap = image::diffHeatmap(reference, frame);

  eval::ParallaxOptions options;
  options.skip_absent = true;  // impostor triangles carry their majority object's id (bench's rule)
  const bool object_ids = std::all_of(ids.pixels().begin(), ids.pixels().end(),
                                      [&](uint32_t id) { return id <= object_count; });
  check.parallax = image::ColorImage(frame.width(), frame.height(), image::Rgba8(0, 0, 0, 255));
  if (object_ids) {
    check.parallax_px = eval::parallaxError(reference_ids, ids, options).object_percentile_px;
    const image::Image<float> map = eval::parallaxErrorMap(reference_ids, ids, options);
    for (size_t i = 0; i < map.pixelCount(); ++i) {
      const float px = map.pixels()[i];
      if (!(px > 0.0f)) continue;
      const float t = std::min(1.0f, px / 32.0f);
      check.parallax.pixels()[i] = image::Rgba8(uint8_t(96 + 159 * t), uint8_t(255 * t * t), 0, 255);
    }
  } else {
    check.parallax_px = std::numeric_limits<double>::quiet_NaN();
  }
  check.bound_px = bound_px;
  check.over_bound = bound_px > 0.0 && check.parallax_px > bound_px;
  return check;
}

}  // namespace farfield::view
