// LOD-sprite rendering, Chen et al. 1999 section 3 (Figure 3) and section 5 (keyframes rendered ahead, keyframe cache).
#include "farfield/terrain/lod_sprite.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "farfield/core/check.h"
#include "farfield/core/error.h"

namespace farfield::terrain {

gpu::FrameStats renderLodFrame(const QuadtreeLod& lod, gpu::TerrainRenderer& renderer, const Camera& camera,
                               const LodSettings& settings, gpu::RenderTarget& target, LodMesh& scratch,
                               const GridRect& hole) {
  lod.build(camera, settings, scratch);
  removeTrianglesInside(scratch, hole, uint32_t(lod.width()));
  renderer.setIndices(scratch.indices, 0);
  return renderer.drawTextured(camera, target, 0, scratch.triangleCount(), 0);
}

std::vector<uint8_t> simulateKeyframes(const QuadtreeLod& lod, const std::vector<Camera>& cameras, float low_error,
                                       double epsilon, std::vector<double>* error_px) {
  std::vector<uint8_t> keyframes(cameras.size(), 0);
  if (error_px) error_px->assign(cameras.size(), 0.0);
  LodMesh low;
  bool have = false;
  Vec3 key_eye(0.0f);
  for (size_t f = 0; f < cameras.size(); ++f) {
    const Camera& camera = cameras[f];
    lod.build(camera, LodSettings{low_error, true, true}, low);
    bool due = !have;
    double shown = 0.0;
    if (have) {
      const SpriteError e = spriteError(lod, low.quadrants, key_eye, camera.eye);
      due = keyframeDue(e, pixelAngle(camera), epsilon);
      shown = e.pixels(pixelAngle(camera));
    }
    if (due) {
      keyframes[f] = 1;
      key_eye = camera.eye;
      have = true;
      shown = 0.0;
    }
    if (error_px) (*error_px)[f] = shown;
  }
  return keyframes;
}

const char* spriteSourceName(SpriteSource source) {
  switch (source) {
    case SpriteSource::Kept: return "kept";
    case SpriteSource::Fresh: return "fresh";
    case SpriteSource::Predicted: return "predicted";
    case SpriteSource::Cached: return "cached";
    case SpriteSource::None: return "none";
  }
  return "?";
}

LodSpriteRenderer::LodSpriteRenderer(const QuadtreeLod& lod, gpu::TerrainRenderer& renderer, int width, int height,
                                     const LodSpriteOptions& options)
    : LodSpriteRenderer(&lod, &renderer, width, height, options) {}

namespace {

// predict_late waits for a keyframe rendered ahead in high frames that cost at most this many sprite frames (by the
// corrected model): with a slice of a third of a sprite frame, under twice a sprite frame.
constexpr double kMildHighFrame = 1.5;

LodSpriteOptions onTheGpu(GpuLodTerrain& terrain, LodSpriteOptions options) {
  if (options.gpu_high && options.gpu_high != &terrain)
    throw Error("lod-sprite", "options name another CDLOD terrain than the renderer's");
  if (!options.gpu_low)
    throw Error("lod-sprite", "a renderer without the quadtree LOD draws its sprite frames on the GPU (gpu_low)");
  options.gpu_high = &terrain;
  return options;
}

}  // namespace

LodSpriteRenderer::LodSpriteRenderer(GpuLodTerrain& terrain, int width, int height, const LodSpriteOptions& options)
    : LodSpriteRenderer(nullptr, nullptr, width, height, onTheGpu(terrain, options)) {}

LodSpriteRenderer::LodSpriteRenderer(const QuadtreeLod* lod, gpu::TerrainRenderer* renderer, int width, int height,
                                     const LodSpriteOptions& options)
    : lod_(lod), renderer_(renderer), width_(width), height_(height), options_(options),
      correction_(options.correction) {
  if (!options.gpu_low && (!lod || !renderer))
    throw Error("lod-sprite", "the sprite frame on the CPU needs the quadtree LOD and its renderer");
  if (!(options.epsilon > 0.0)) throw Error("lod-sprite", "error threshold epsilon must be positive (pixels)");
  if (!(options.high_error > 0.0f) || !(options.low_error >= options.high_error))
    throw Error("lod-sprite", "need 0 < high-resolution error <= low-resolution error (pixels)");
  if (options.predict_history < 2 || options.predict_chunks < 1)
    throw Error("lod-sprite", "prediction needs at least 2 viewpoints of history and 1 chunk");
  if (options.cache_size < 1) throw Error("lod-sprite", "cache size must be at least 1 (the current keyframe)");
  if (!(options.predict_lead > 0.0f)) throw Error("lod-sprite", "prediction lead must be positive");
  if (width < 1 || height < 1) throw Error("lod-sprite", "frame size must be positive");
  if (!(options.keyframe_margin >= 0.0f && options.keyframe_margin <= 1.0f))
    throw Error("lod-sprite", "keyframe margin must be 0..1 (share of the frame size per side)");
  if (options.lifetime_history < 1) throw Error("lod-sprite", "lifetime history must be at least 1 sprite");
  if (!(options.max_magnification == 0.0 || options.max_magnification > 1.0))
    throw Error("lod-sprite", "the largest magnification must be above 1 (0: not bounded)");
  if (options.gpu_high && options.cost && !options.cost->gpu_high)
    throw Error("lod-sprite", "the CDLOD high LOD needs a cost model fitted on its frames (TerrainCostOptions::gpu_high)");
  if (options.gpu_low) {
    if (!options.gpu_high)
      throw Error("lod-sprite", "the sprite frame on the GPU (gpu_low) needs the CDLOD terrain (gpu_high)");
    if (!options.gpu_high->holdsGridHeights())
      throw Error("lod-sprite", "the terrain must keep its pages' heights (PagedGpuLodOptions::keep_heights): the error "
                                "metric reads the grid's heights, and the overview alone would under-count it near the "
                                "eye");
    if (options.cost && !options.cost->gpu_sprite)
      throw Error("lod-sprite",
                  "the sprite frame on the GPU needs a cost model fitted on its frames (TerrainCost::gpu_sprite)");
    warmUpSpriteFrame();
  }
}

void LodSpriteRenderer::warmUpSpriteFrame() {
  // One sprite frame of 8 x 8 pixels over the terrain's middle, with the renderer's hole: the driver makes the
  // program's code at its first draw (llvmpipe: tens of milliseconds), which would otherwise be the first sprite
  // frame's (a 104 ms frame on the city-on-terrain drive).
  const Box3 box = options_.gpu_high->bounds();
  const Vec3 extent = box.hi - box.lo;
  Camera c;
  c.width = c.height = 8;
  c.at = Vec3(box.lo.x + 0.5f * extent.x, box.lo.y + 0.5f * extent.y, box.lo.z);
  c.eye = c.at + Vec3(0.0f, -0.5f * extent.y, extent.z + 100.0f);
  c.far_plane = 4.0f * (extent.x + extent.y) + 1000.0f;
  gpu::RenderTarget key(8, 8), frame(8, 8);
  key.clear(options_.sky_color);
  frame.clear(options_.sky_color);
  drawCdlodSprite(c, options_.gpu_high->select(c, options_.low_error), frame, c, key);
  // The selections of the frame's size at both bounds and of the keyframe's at the high one: the first selection at
  // a new scale makes its node ranges (30 ms on the 16,385^2 terrain), which was otherwise the first keyframe's frame
  // (49 ms against 6 for the CDLOD frame there); the terrain's range slots keep them. For a camera of Camera's field
  // of view.
  Camera view = c;
  view.width = width_;
  view.height = height_;
  options_.gpu_high->select(keyframeCamera(view), options_.high_error);
  options_.gpu_high->select(view, options_.high_error);
  options_.gpu_high->select(view, options_.low_error);
  options_.gpu_high->renderer().finish();
}

gpu::FrameStats LodSpriteRenderer::drawHigh(const Camera& camera, gpu::RenderTarget& target, LodMesh& mesh, int slot) {
  if (options_.gpu_high) {
    options_.gpu_high->setHole(options_.hole);
    const gpu::FrameStats stats = options_.gpu_high->draw(camera, options_.high_error, target).draw;
    options_.gpu_high->clearHole();
    return stats;
  }
  lod_->build(camera, LodSettings{options_.high_error, true, false}, mesh);
  removeTrianglesInside(mesh, options_.hole, uint32_t(lod_->width()));
  renderer_->setIndices(mesh.indices, slot);
  return renderer_->drawTextured(camera, target, 0, mesh.triangleCount(), slot);
}

LodSpriteRenderer::~LodSpriteRenderer() = default;

void LodSpriteRenderer::reset() {
  for (auto& k : kept_) spare_.push_back(std::move(k));
  kept_.clear();
  if (pending_) spare_.push_back(std::move(pending_));
  current_ = nullptr;
  counters_ = {};
  frame_ = 0;
  sprite_since_ = 0;
  sprite_error_at_take_ = 0.0;
  last_progress_ = 0.0;
  last_error_px_ = 0.0;
  last_progress_frame_ = 0;
  last_lifetime_ = 10;
  pending_chunk_ = 0;
  pending_chunks_ = 1;
  history_.clear();
  anchored_ = false;
  anchor_since_ = 0;
  lifetimes_.clear();
  high_triangles_frame_ = high_triangles_key_ = 0;
  high_latest_is_key_ = false;
  error_sample_.clear();
  correction_.reset();
}

bool LodSpriteRenderer::measured(uint64_t frame, double ms) {
  return options_.cost != nullptr && correction_.measured(frame, ms);
}

gpu::FrameStats LodSpriteRenderer::finish(const gpu::FrameStats& stats, LodSpriteFrameInfo& info,
                                          LodSpriteFrameInfo* out) {
  const PathCosts& m = model_costs_;
  double base = m.sprite_ms, extra = 0.0;
  if (info.path == TerrainPath::High) {
    info.kind = TerrainFrameKind::High;
    base = m.high_ms;
  } else if (info.source == SpriteSource::Fresh) {
    info.kind = TerrainFrameKind::Keyframe;
    extra = std::max(m.keyframe_ms - m.sprite_ms, 0.0);
  } else if (info.ahead_triangles > 0) {
    info.kind = TerrainFrameKind::Slice;
    extra = std::max(m.keyframe_ms - m.sprite_ms, 0.0) * double(std::max<size_t>(info.ahead_slices, 1)) /
            double(std::max<size_t>(pending_chunks_, 1));
  } else {
    info.kind = TerrainFrameKind::Sprite;
  }
  if (options_.cost) correction_.drawn(frame_, info.kind, base, extra);
  if (out) *out = info;
  return stats;
}

PathCosts LodSpriteRenderer::correctedCosts(const PathCosts& model) const {
  PathCosts c;
  c.high_ms = model.high_ms * correction_.factor(TerrainFrameKind::High);
  c.sprite_ms = model.sprite_ms * correction_.factor(TerrainFrameKind::Sprite);
  c.keyframe_ms =
      c.sprite_ms + std::max(model.keyframe_ms - model.sprite_ms, 0.0) * correction_.factor(TerrainFrameKind::Keyframe);
  return c;
}

const Camera* LodSpriteRenderer::spriteCamera() const { return current_ ? &current_->camera : nullptr; }
const gpu::RenderTarget* LodSpriteRenderer::spriteTarget() const { return current_ ? &current_->target : nullptr; }
const image::DepthImage* LodSpriteRenderer::spriteDepth() const { return current_ ? &current_->depth : nullptr; }

double LodSpriteRenderer::progressPx(double error_px, double magnification) const {
  const double m = options_.max_magnification;
  if (m > 0.0) error_px = std::max(error_px, options_.epsilon * (magnification - 1.0) / (m - 1.0));
  return error_px;
}

bool LodSpriteRenderer::dueAt(const SpriteError& e, double beta, double share) const {
  const double m = options_.max_magnification;
  return keyframeDue(e, beta, share * options_.epsilon, m > 0.0 ? 1.0 + share * (m - 1.0) : 0.0);
}

SpriteError LodSpriteRenderer::frameError(const Vec3& v1, const Vec3& v2) const {
  if (options_.gpu_low) {
    const GpuLodTerrain& terrain = *options_.gpu_high;
    return error_sample_.measure(
        terrain.lod(),
        [&terrain](std::span<const IVec2> points, std::span<float> out, std::span<uint8_t> own) {
          terrain.gridHeights(points, out, own);
        },
        terrain.heightsVersion(), terrain.selection(low_handle_).nodes, v1, v2, options_.error_quadrants);
  }
  return spriteError(*lod_, low_.quadrants, v1, v2);
}

gpu::FrameStats LodSpriteRenderer::drawCdlodSprite(const Camera& camera, int handle, gpu::RenderTarget& target,
                                                   const Camera& key_camera, const gpu::RenderTarget& key) {
  GpuLodTerrain& terrain = *options_.gpu_high;
  gpu::CdlodSprite sprite;
  sprite.colour = &key.colorTexture();
  sprite.depth = &key.depthTexture();
  sprite.camera = key_camera;
  sprite.thickness_m = options_.visibility.thickness_m;
  sprite.thickness_rel = options_.visibility.thickness_rel;
  sprite.footprint_pixels = options_.visibility.footprint_pixels;
  terrain.renderer().setSprite(sprite);
  terrain.setHole(options_.hole);
  const gpu::FrameStats stats = terrain.drawSelection(camera, handle, target).draw;
  terrain.clearHole();
  terrain.renderer().clearSprite();
  return stats;
}

PathCosts LodSpriteRenderer::modelCosts(size_t low_triangles) const {
  const TerrainCost& c = *options_.cost;
  const Camera key = keyframeCamera(Camera{});
  const double area_ratio = double(key.width) * double(key.height) / (double(width_) * double(height_));
  // The high LOD's size changes slowly along a path: the latest count seen (at the frame's or at a keyframe's camera)
  // stands for this frame's, scaled by the image area for the other camera.
  double frame_tris = double(high_triangles_frame_), key_tris = double(high_triangles_key_);
  if (high_latest_is_key_) frame_tris = key_tris / area_ratio;
  else key_tris = frame_tris * area_ratio;
  PathCosts p;
  const bool gpu = options_.gpu_high != nullptr;
  p.high_ms = gpu ? c.gpuHighMs(frame_tris, width_, height_) : c.frameMs(frame_tris, 1.0, width_, height_);
  p.sprite_ms = options_.gpu_low ? c.gpuSpriteMs(double(low_triangles), width_, height_)
                                 : c.frameMs(double(low_triangles), 2.0, width_, height_);
  p.keyframe_ms = (gpu ? c.gpuHighMs(key_tris, key.width, key.height) : c.frameMs(key_tris, 1.0, key.width, key.height)) +
                  (options_.gpu_low ? 0.0 : c.readbackMs(key.width, key.height)) + p.sprite_ms;
  return p;
}

gpu::FrameStats LodSpriteRenderer::renderHigh(const Camera& camera, gpu::RenderTarget& target,
                                              LodSpriteFrameInfo& info) {
  info.path = TerrainPath::High;
  ++counters_.high_frames;
  const gpu::FrameStats stats = drawHigh(camera, target, high_, 0);
  info.high_triangles = stats.triangles;
  high_triangles_frame_ = stats.triangles;
  high_latest_is_key_ = false;
  return stats;
}

gpu::FrameStats LodSpriteRenderer::render(const Camera& camera, gpu::RenderTarget& target, LodSpriteFrameInfo* out) {
  if (camera.width != width_ || camera.height != height_)
    throw Error("lod-sprite", "camera size differs from the renderer's frame size");
  ++frame_;
  ++counters_.frames;
  LodSpriteFrameInfo info;
  info.frame = frame_;
  gpu::FrameStats stats;
  history_.emplace_back(camera.eye, camera.at);
  while (history_.size() > size_t(options_.predict_history)) history_.pop_front();

  // Figure 3, line 6 (done first: the error metric of line 3 runs over this mesh's quadrants).
  if (options_.gpu_low) {
    low_handle_ = options_.gpu_high->select(camera, options_.low_error);
    const CdlodSelection& low = options_.gpu_high->selection(low_handle_);
    low_triangles_ = low.nodes.size() * options_.gpu_high->renderer().trianglesPerNode();
  } else {
    lod_->build(camera, LodSettings{options_.low_error, true, true}, low_);
    removeTrianglesInside(low_, options_.hole, uint32_t(lod_->width()));
    info.quadrants = low_.quadrants.size();
    low_triangles_ = low_.triangleCount();
  }
  const double beta = pixelAngle(camera);
  auto errorOf = [&](const Keyframe& k) { return frameError(k.camera.eye, camera.eye); };
  const bool choose = options_.cost != nullptr;
  PathCosts costs;
  if (choose) {
    model_costs_ = modelCosts(low_triangles_);
    info.predicted_high_ms = model_costs_.high_ms;
    info.predicted_sprite_ms = model_costs_.sprite_ms;
    info.predicted_keyframe_ms = model_costs_.keyframe_ms;
    costs = correctedCosts(model_costs_);
  }
  // The sprite frame on the GPU, where a sprite frame costs no less than the high LOD: no sprite can pay (a keyframe
  // costs a sprite frame more), so the frame is the high LOD without the error metric, whose sampled cells are most
  // of this path's CPU time (on a smooth terrain the 4 px CDLOD mesh is nearly the 1 px one). The virtual keyframe
  // stays where it was; the metric resumes when sprites are cheaper again.
  if (options_.gpu_low && choose && costs.sprite_ms >= costs.high_ms) {
    info.source = SpriteSource::None;
    return finish(renderHigh(camera, target, info), info, out);
  }

  // predict_late: a keyframe rendered ahead is taken as soon as it is ready, where it has less error than the current
  // sprite and covers the view, or covers it at least as well as the current sprite (which is in use anyway);
  // otherwise it is stale (the camera went elsewhere than extrapolated) and dropped, so that a new one is made. Its
  // error is measured first: where it is under the current sprite's of the last frame (an error that grows), it is
  // taken without measuring the current sprite here, a measure saved in the frames that take one (two measures, one
  // projecting every sampled cell, made them the paged flight's 95th percentile of own CPU time).
  bool early = false;
  double early_error = 0.0;  // the early-taken keyframe's error here (pixels)
  SpriteError early_metric;
  const bool ready_ahead = options_.predict_late && anchored_ && current_ && pending_ && pending_->ready;
  std::optional<bool> covers;  // coversView(*pending_, current_), once asked
  auto coversNow = [&] {
    if (!covers) covers = coversView(*pending_, current_);
    return *covers;
  };
  // Taken early where it has less error than `current_error` (the current sprite's) and some life left.
  auto takenEarly = [&](double current_error) {
    return early_error < current_error && early_error < 0.75 * options_.epsilon && coversNow();
  };
  if (ready_ahead) {
    early_metric = frameError(pending_->camera.eye, camera.eye);
    early_error = early_metric.pixels(beta);
    early = lastFrameDrewCurrentSprite() && takenEarly(last_error_px_);
    if (early) {
      if (options_.gpu_low) info.quadrants = early_metric.quadrants;
      info.trigger_error_px = last_error_px_;
    }
  }

  // Lines 3-5: error of the current sprite (or of the virtual keyframe the high LOD stands for); a new one when it
  // reaches the threshold.
  bool due = !anchored_;
  if (anchored_ && !early) {
    const SpriteError e = frameError(anchor_eye_, camera.eye);
    if (options_.gpu_low) info.quadrants = e.quadrants;
    info.trigger_error_px = info.error_px = e.pixels(beta);
    info.magnification = e.mean_magnification;
    due = dueAt(e, beta, 1.0);
  }
  info.keyframe_due = due;
  // While the high LOD stands in for a virtual keyframe, that keyframe has already lasted `age` frames: a sprite
  // lives at least that long here, so a keyframe may be taken now, before the metric trips, when that pays (the run's
  // first sprite has no lifetime measured yet, and a sprite that would last the whole path never trips).
  // predict_late: where a high frame costs little more than a sprite frame, the switch waits for a keyframe rendered
  // ahead in slices with the high frames before it (taken as a predicted one), instead of drawing a whole keyframe in
  // its frame (4-5 times a sprite frame); where high frames cost more (the 16,385^2 flight's low passes: 3-4 times a
  // sprite frame), waiting in them would cost more than the whole keyframe, which is drawn as before.
  const bool ahead_of_switch =
      options_.predict && options_.predict_late && choose && costs.high_ms <= kMildHighFrame * costs.sprite_ms;
  bool switch_now = false, sprite_pays = false;
  if (!due && !current_ && choose) {
    const double age = double(frame_ - anchor_since_);
    info.expected_lifetime = std::max(spriteLifetimeEstimate(lifetimes_, 1.0), age);
    sprite_pays = choosePath(costs, false, info.expected_lifetime) == TerrainPath::Sprite;
    switch_now = sprite_pays && (!ahead_of_switch || (pending_ && pending_->ready));
  }
  info.switched = switch_now;
  if (ready_ahead && !early && !due) {
    early = takenEarly(info.error_px);
    if (!early) {
      ++counters_.predicted_discarded;
      spare_.push_back(std::move(pending_));
    }
  }
  if (due || switch_now || early) {
    if (due && anchored_) {
      last_lifetime_ = std::max<uint64_t>(frame_ - anchor_since_, 1);
      lifetimes_.push_back(last_lifetime_);
      while (lifetimes_.size() > size_t(options_.lifetime_history)) lifetimes_.pop_front();
    }
    anchored_ = true;
    anchor_eye_ = camera.eye;
    anchor_since_ = frame_;
    Keyframe* chosen = nullptr;
    double chosen_error = 0.0;
    SpriteError chosen_metric;  // its metric here, measured once (the magnification below is read from it)
    // A keyframe rendered ahead that the trip caught with at most half of its slices left (the error's rate, or the
    // magnification's, rose faster than the schedule saw): its last slices now, a fraction of a fresh keyframe, then
    // the same test as a ready one. On the 16,385^2 flight the fresh keyframes at a trip were caught one or three
    // slices short of 8-11.
    // (The quadtree's step 0 builds its mesh and draws no slice.)
    const size_t sliced = options_.gpu_high || pending_chunk_ == 0 ? pending_chunk_ : pending_chunk_ - 1;
    if (options_.predict && pending_ && !pending_->ready && 2 * sliced >= pending_chunks_) {
      while (!pending_->ready) advancePrediction(stats, info);
      ++counters_.predicted_finished;
    }
    if (pending_ && pending_->ready) {
      // Taken with some life left (error at most 3/4 of the threshold here, and magnification at most 3/4 of the way
      // to its bound; it would trip again at once otherwise) where it covers the view. Its metric here was measured
      // above where it was ready at the frame's start.
      const SpriteError m = ready_ahead ? early_metric : frameError(pending_->camera.eye, camera.eye);
      if (early || (!dueAt(m, beta, 0.75) && coversNow())) {
        chosen = pending_.get();
        chosen_metric = m;
        chosen_error = early ? early_error : m.pixels(beta);
        info.source = SpriteSource::Predicted;
        ++counters_.predicted_used;
        keep(std::move(pending_));
      }
    }
    if (!chosen && options_.cache_size > 1) {
      double best = std::numeric_limits<double>::max();
      for (auto& k : kept_) {
        if (k.get() == current_) continue;
        const SpriteError e = errorOf(*k);
        if (dueAt(e, beta, 1.0) || e.mean_theta_sq >= best) continue;
        if (!coversView(*k, current_)) continue;
        best = e.mean_theta_sq;
        chosen = k.get();
        chosen_error = e.pixels(beta);
        chosen_metric = e;
      }
      if (chosen) {
        info.source = SpriteSource::Cached;
        ++counters_.cache_hits;
      }
    }
    if (chosen) anchor_eye_ = chosen->camera.eye;  // a reused sprite's error is measured from its own viewpoint
    if (!chosen && choose && (ahead_of_switch || !switch_now)) {
      info.expected_lifetime = spriteLifetimeEstimate(lifetimes_, 1.0);
      sprite_pays = choosePath(costs, false, info.expected_lifetime) == TerrainPath::Sprite;
      if (!sprite_pays || ahead_of_switch) {
        // No keyframe: this frame is the high LOD, and the metric goes on from a virtual keyframe here (predict_late:
        // the next keyframe is rendered ahead of the switch; one that was refused here is dropped).
        current_ = nullptr;
        ++counters_.virtual_keyframes;
        info.switched = false;  // the keyframe it waited for was refused: no switch
        info.source = SpriteSource::None;
        info.error_px = 0.0;
        if (pending_ && pending_->ready) {
          ++counters_.predicted_discarded;
          spare_.push_back(std::move(pending_));
        }
        gpu::FrameStats high = renderHigh(camera, target, info);
        if (sprite_pays) renderAheadOfSwitch(camera, high, info);
        return finish(high, info, out);
      }
    }
    if (!chosen) {
      chosen = renderKeyframe(camera, stats, info);
      chosen_error = 0.0;
      info.source = SpriteSource::Fresh;
    }
    if (switch_now) ++counters_.switches;
    current_ = chosen;
    info.magnification = info.source == SpriteSource::Fresh ? 1.0 : chosen_metric.mean_magnification;
    sprite_since_ = frame_;
    sprite_error_at_take_ = chosen_error;
    info.error_px = chosen_error;
    if (!options_.gpu_low) visibility_.reset(*lod_, current_->camera, &current_->depth, options_.visibility);
    if (pending_ && options_.predict_late) {
      // Not taken: a new one is made when this sprite is about to trip.
      ++counters_.predicted_discarded;
      spare_.push_back(std::move(pending_));
    }
    if (options_.predict && !options_.predict_late) {
      // As many frames ahead as the previous sprite lasted (times the lead; at least long enough to finish drawing
      // it), ready by about half of that lifetime: at most predict_chunks slices, fewer for short-lived sprites.
      schedulePrediction(camera, std::clamp(float(last_lifetime_) * options_.predict_lead, 2.0f, 600.0f),
                         size_t(std::clamp<uint64_t>(last_lifetime_ / 2, 1, uint64_t(options_.predict_chunks))));
    }
  } else if (!current_ || (choose && choosePath(costs, true, 0.0) == TerrainPath::High)) {
    // A virtual keyframe still valid, or a valid sprite that costs more to draw than the high LOD.
    info.source = SpriteSource::None;
    gpu::FrameStats high = renderHigh(camera, target, info);
    if (ahead_of_switch && sprite_pays && !current_) renderAheadOfSwitch(camera, high, info);
    return finish(high, info, out);
  }
  current_->last_used = frame_;
  if (options_.predict && options_.predict_late && !due) {
    const double progress = progressPx(info.error_px, info.magnification);
    if (!pending_) scheduleLatePrediction(camera, progress, choose ? &model_costs_ : nullptr);
    last_progress_ = progress;
    last_error_px_ = info.error_px;
    last_progress_frame_ = frame_;
  }

  // Section 5: the keyframe rendered ahead, one step per frame, from the frame after a switch on (the switch frame
  // may already have drawn a whole keyframe).
  if (options_.predict && pending_ && !pending_->ready && !due) advancePrediction(stats, info);

  // Lines 7-11: visible triangles with the sprite, the others with the original texture.
  if (options_.gpu_low) {
    if (info.source == SpriteSource::Fresh && (options_.predict || options_.cache_size > 1))
      current_->coverage_at_creation = coverage(*current_);
    const gpu::FrameStats sprite = drawCdlodSprite(camera, low_handle_, target, current_->camera, current_->target);
    info.low_triangles = sprite.triangles;
    gpu::addDraw(stats, sprite);
    return finish(stats, info, out);
  }
  const size_t n = low_.triangleCount();
  const size_t visible = visibility_.partition(low_.indices);
  if (info.source == SpriteSource::Fresh) current_->coverage_at_creation = n ? double(visible) / double(n) : 1.0;
  renderer_->setIndices(low_.indices, 0);
  gpu::addDraw(stats, renderer_->drawSprite(camera, target, current_->target.colorTexture(), current_->view_proj, 0,
                                            visible, 0));
  gpu::addDraw(stats, renderer_->drawTextured(camera, target, visible, n - visible, 0));
  info.low_triangles = n;
  info.visible_triangles = visible;
  return finish(stats, info, out);
}

}  // namespace farfield::terrain
