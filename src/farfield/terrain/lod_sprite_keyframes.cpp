// LOD-sprite's keyframes (Chen et al. 1999, Figure 3, lines 1 and 5): their pool, their camera with its guard band,
// the cache that keeps the most recent ones, and a keyframe rendered whole in the frame that needs it.
#include <algorithm>
#include <cmath>

#include "farfield/terrain/lod_sprite.h"

namespace farfield::terrain {

std::unique_ptr<LodSpriteRenderer::Keyframe> LodSpriteRenderer::takeKeyframe() {
  if (!spare_.empty()) {
    std::unique_ptr<Keyframe> k = std::move(spare_.back());
    spare_.pop_back();
    k->ready = false;
    return k;
  }
  auto k = std::make_unique<Keyframe>();
  const Camera size = keyframeCamera(Camera{});
  k->target = gpu::RenderTarget(size.width, size.height);
  return k;
}

Camera guardBandCamera(const Camera& camera, int width, int height, float margin) {
  Camera frame = camera;
  frame.width = width;
  frame.height = height;
  return frame.resized(width + 2 * int(std::lround(margin * float(width))),
                       height + 2 * int(std::lround(margin * float(height))));
}

Camera LodSpriteRenderer::keyframeCamera(const Camera& camera) const {
  return guardBandCamera(camera, width_, height_, options_.keyframe_margin);
}

void LodSpriteRenderer::keep(std::unique_ptr<Keyframe> keyframe) {
  // Least recently used out first; the current sprite is never evicted here (it is about to be replaced by the new
  // one, but it was used in the previous frame, so it is the most recent of the others).
  while (!kept_.empty() && kept_.size() >= size_t(options_.cache_size)) {
    auto oldest = std::min_element(kept_.begin(), kept_.end(),
                                   [](const auto& a, const auto& b) { return a->last_used < b->last_used; });
    if (oldest->get() == current_) current_ = nullptr;
    spare_.push_back(std::move(*oldest));
    kept_.erase(oldest);
  }
  kept_.push_back(std::move(keyframe));
}

LodSpriteRenderer::Keyframe* LodSpriteRenderer::renderKeyframe(const Camera& camera, gpu::FrameStats& stats,
                                                              LodSpriteFrameInfo& info) {
  std::unique_ptr<Keyframe> k = takeKeyframe();
  k->frame_camera = camera;
  k->camera = keyframeCamera(camera);
  k->view_proj = k->camera.viewProjection();
  // Figure 3, lines 1 and 5: the high-resolution mesh rendered into the sprite; then the z-buffer is kept.
  k->target.clear(options_.sky_color);
  const gpu::FrameStats key = drawHigh(k->camera, k->target, high_, 0);
  gpu::addDraw(stats, key);
  info.keyframe_triangles += key.triangles;
  high_triangles_key_ = key.triangles;
  high_latest_is_key_ = true;
  if (!options_.gpu_low) k->depth = k->target.readDepth();  // gpu_low: tested against on the GPU
  k->ready = true;
  ++counters_.fresh_keyframes;
  Keyframe* raw = k.get();
  keep(std::move(k));
  return raw;
}

}  // namespace farfield::terrain
