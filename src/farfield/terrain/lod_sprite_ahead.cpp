// LOD-sprite's keyframes rendered ahead (Chen et al. 1999, section 5) and the test that a kept or predicted keyframe
// may take over: scheduling (right after a sprite is taken, or late, when its error says it is about to trip), the
// slices each frame draws, and the view coverage.
#include <algorithm>
#include <cmath>

#include "farfield/core/error.h"
#include "farfield/terrain/lod_sprite.h"

namespace farfield::terrain {
namespace {

// A slice of a keyframe rendered ahead late costs at most this share of a sprite frame by the cost model, corrected
// by the measured frames where they are reported (before that, on llvmpipe, whose sprite frames measure 1.2-1.5x the
// model's prediction: about half a sprite frame measured).
constexpr double kSliceShare = 1.0 / 3.0;

}  // namespace

double LodSpriteRenderer::slicesFor(const PathCosts& model) const {
  // The slices' measured share of the keyframe's predicted part, over a sprite frame's measured cost.
  const double slice = std::max(model.keyframe_ms - model.sprite_ms, 0.0) * correction_.factor(TerrainFrameKind::Slice);
  const double sprite = model.sprite_ms * correction_.factor(TerrainFrameKind::Sprite);
  return sprite > 0.0 ? std::ceil(slice / (kSliceShare * sprite)) : double(options_.predict_chunks);
}

double LodSpriteRenderer::coverage(Keyframe& keyframe) {
  if (options_.gpu_low) return nodeCoverage(options_.gpu_high->selection(low_handle_).nodes, keyframe);
  probe_.reset(*lod_, keyframe.camera, &keyframe.depth, options_.visibility);
  return probe_.visibleShare(low_.indices);
}

double LodSpriteRenderer::nodeCoverage(std::span<const CdlodNode> nodes, const Keyframe& keyframe) const {
  // Every node is a patch of the same triangles: the share of nodes stands for the share of triangles.
  if (nodes.empty()) return 1.0;
  const CdlodTerrain& lod = options_.gpu_high->lod();
  size_t inside = 0;
  for (const CdlodNode& n : nodes) {
    const Vec4 p = keyframe.view_proj * Vec4(lod.nodeBox(n).center(), 1.0f);
    if (p.w > 0.0f && std::abs(p.x) <= p.w && std::abs(p.y) <= p.w) ++inside;
  }
  return double(inside) / double(nodes.size());
}

void LodSpriteRenderer::schedulePrediction(const Camera& camera, float ahead, size_t chunks) {
  if (pending_) {
    ++counters_.predicted_discarded;
    spare_.push_back(std::move(pending_));
  }
  // Linear extrapolation of eye and look-at over the recent viewpoints, `ahead` frames ahead.
  const size_t n = history_.size();
  Vec3 eye_velocity(0.0f), at_velocity(0.0f);
  if (n >= 2) {
    eye_velocity = (history_.back().first - history_.front().first) / float(n - 1);
    at_velocity = (history_.back().second - history_.front().second) / float(n - 1);
  }
  Camera predicted = camera;
  predicted.eye = camera.eye + eye_velocity * ahead;
  predicted.at = camera.at + at_velocity * ahead;
  if (options_.predict_late && n >= 2) {
    // Late: the direction turned at its recent angular rate (the look-at point's distance changes with the path, so
    // its linear extrapolation turns the view by other angles); at most 30 degrees.
    const Vec3 f0 = glm::normalize(history_.front().second - history_.front().first);
    const Vec3 f1 = camera.forward();
    const Vec3 axis = glm::cross(f0, f1);
    const float turned = std::atan2(glm::length(axis), glm::dot(f0, f1));
    Vec3 f = f1;
    if (glm::length(axis) > 1e-6f) {
      const float angle = std::min(turned / float(n - 1) * ahead, glm::radians(30.0f));
      f = f1 * std::cos(angle) + glm::cross(glm::normalize(axis), f1) * std::sin(angle);  // axis is normal to f1
    }
    predicted.at = predicted.eye + f * glm::length(camera.at - camera.eye);
  }
  // Never extrapolate into the ground (a descent would otherwise end below the terrain): keep at least half of the
  // current height above the ground.
  auto ground = [&](const Vec3& p) {
    return options_.gpu_high ? options_.gpu_high->groundHeight(p.x, p.y) : lod_->heightfield().sample(p.x, p.y);
  };
  const float ground_now = ground(camera.eye);
  const float ground_then = ground(predicted.eye);
  predicted.eye.z = std::max(predicted.eye.z, ground_then + 0.5f * std::max(camera.eye.z - ground_now, 0.0f));
  if (glm::length(predicted.at - predicted.eye) < 1e-3f) predicted.at = predicted.eye + camera.forward();
  try {
    predicted.validate("predicted keyframe camera");
  } catch (const Error&) {
    return;  // e.g. extrapolated into looking straight up: no prediction this time
  }
  pending_ = takeKeyframe();
  pending_->frame_camera = predicted;
  pending_->camera = keyframeCamera(predicted);
  pending_->view_proj = pending_->camera.viewProjection();
  pending_chunk_ = 0;
  pending_chunks_ = chunks;
}

void LodSpriteRenderer::advancePrediction(gpu::FrameStats& stats, LodSpriteFrameInfo& info) {
  Keyframe& k = *pending_;
  size_t chunks = pending_chunks_;
  if (options_.gpu_high) {
    // The CDLOD terrain: step 0 selects its nodes (on the CPU; kept here, as the terrain's selections are remade by
    // the frames in between); steps 0..chunks-1 draw one run of them each.
    GpuLodTerrain& terrain = *options_.gpu_high;
    if (pending_chunk_ == 0) {
      terrain.lod().select(k.camera, options_.high_error, true, pending_selection_);
      k.target.clear(options_.sky_color);
      // The freshest count of a keyframe's triangles, for the next predictions (modelCosts).
      high_triangles_key_ = pending_selection_.nodes.size() * terrain.renderer().trianglesPerNode();
      high_latest_is_key_ = true;
      // Late: the slices sized from this keyframe's own triangles, now known, where the schedule had the last
      // keyframe's: more of them where it is larger (never fewer than scheduled; at most predict_chunks).
      if (options_.predict_late && options_.cost) {
        const PathCosts model = modelCosts(low_triangles_);
        if (model.sprite_ms > 0.0) {
          chunks = std::max(chunks, size_t(std::clamp(slicesFor(model), 1.0, double(options_.predict_chunks))));
          if (pending_most_ > 0) chunks = std::min(chunks, pending_most_);
          pending_chunks_ = chunks;
        }
      }
    }
    const std::span<const CdlodNode> nodes = pending_selection_.nodes;
    const size_t per_chunk = (nodes.size() + chunks - 1) / chunks;
    const size_t first = std::min(nodes.size(), pending_chunk_ * per_chunk);
    terrain.setHole(options_.hole);
    const std::span<const CdlodNode> run = nodes.subspan(first, std::min(nodes.size() - first, per_chunk));
    const gpu::FrameStats ahead = terrain.drawNodes(k.camera, options_.high_error, run, k.target).draw;
    terrain.clearHole();
    gpu::addDraw(stats, ahead);
    info.ahead_triangles += ahead.triangles;
    ++info.ahead_slices;
    if (++pending_chunk_ < chunks) return;
  } else {
    // The quadtree LOD: step 0 (the frame after the switch) builds the mesh; steps 1..chunks draw one slice of it each.
    if (pending_chunk_ == 0) {
      lod_->build(k.camera, LodSettings{options_.high_error, true, false}, pending_mesh_);
      removeTrianglesInside(pending_mesh_, options_.hole, uint32_t(lod_->width()));
      renderer_->setIndices(pending_mesh_.indices, 1);
      k.target.clear(options_.sky_color);
      ++pending_chunk_;
      return;
    }
    const size_t total = pending_mesh_.triangleCount();
    const size_t per_chunk = (total + chunks - 1) / chunks;
    const size_t first = std::min(total, (pending_chunk_ - 1) * per_chunk);
    const size_t count = std::min(total - first, per_chunk);
    gpu::addDraw(stats, renderer_->drawTextured(k.camera, k.target, first, count, 1));
    info.ahead_triangles += count;
    ++info.ahead_slices;
    if (++pending_chunk_ <= chunks) return;
  }
  k.ready = true;
  ++counters_.predicted_rendered;
  // Its own coverage, for the reuse test: the low-resolution mesh at its viewpoint, against its z-buffer (read here;
  // the sprite frame on the GPU reads nothing and tests the CDLOD nodes against its image instead).
  if (options_.gpu_low) {
    options_.gpu_high->lod().select(k.frame_camera, options_.low_error, true, probe_selection_);
    k.coverage_at_creation = nodeCoverage(probe_selection_.nodes, k);
    return;
  }
  k.depth = k.target.readDepth();
  lod_->build(k.frame_camera, LodSettings{options_.low_error, true, false}, probe_mesh_);
  probe_.reset(*lod_, k.camera, &k.depth, options_.visibility);
  k.coverage_at_creation = probe_.visibleShare(probe_mesh_.indices);
}

void LodSpriteRenderer::renderAheadOfSwitch(const Camera& camera, gpu::FrameStats& stats, LodSpriteFrameInfo& info) {
  if (!pending_) {
    // Slices of at most kSliceShare of a sprite frame each by the cost model (at most predict_chunks of them), from
    // where the camera will be when it is ready, which is when the switch takes it.
    const double chunks = std::clamp(slicesFor(model_costs_), 1.0, double(options_.predict_chunks));
    pending_most_ = 0;
    schedulePrediction(camera, float(chunks), size_t(chunks));
  }
  if (pending_ && !pending_->ready) advancePrediction(stats, info);
}

void LodSpriteRenderer::scheduleLatePrediction(const Camera& camera, double error_px, const PathCosts* model) {
  // The error grows roughly with the distance moved since the sprite was taken; at the rate seen since then, or at
  // the last frame's where it grows faster (the magnification of a descent towards the ground grows as the inverse of
  // the height: the rate since the take put trips one to three frames after they came), it trips in `left` frames. The
  // next keyframe is started once about 1.5 times the frames it is drawn in are left, or once the error has reached
  // 3/4 of the threshold (an error that creeps near the threshold for a long time trips at a jump the rate does not
  // see).
  const double age = double(frame_ - sprite_since_);
  const double grown = error_px - sprite_error_at_take_;
  if (age < 2.0 || !(grown > 0.05 * options_.epsilon)) return;
  double rate = grown / age;
  if (lastFrameDrewCurrentSprite()) rate = std::max(rate, error_px - last_progress_);
  const double left = (options_.epsilon - error_px) / rate;
  // Slices of at most kSliceShare of a sprite frame each by the cost model (at most predict_chunks of them).
  double chunks = double(options_.predict_chunks);
  if (model && model->sprite_ms > 0.0) chunks = std::clamp(slicesFor(*model), 1.0, chunks);
  if (left > 1.5 * chunks + 1.0 && error_px < 0.75 * options_.epsilon) return;
  // Ready before the trip: where the rate leaves fewer frames than the slices the cost model wants (sprites that
  // live 8-10 frames on the 16,385^2 flight's descent, keyframes of 14 slices there), larger slices, one a frame until
  // the frame before the trip; a keyframe that is not ready when the sprite trips is drawn whole after its slices
  // (15 such frames of 40-60 ms in 600, against a median of 13).
  pending_most_ = 0;
  const double fit = std::floor(left - 1.0);
  if (fit >= 2.0 && fit < chunks) {
    chunks = fit;
    pending_most_ = size_t(fit);
  }
  // From where the camera will be when it is ready, which is when it is taken (it then has less error than the
  // current sprite): a short extrapolation.
  schedulePrediction(camera, float(chunks), size_t(chunks));
}

bool LodSpriteRenderer::coversView(Keyframe& keyframe, Keyframe* replaced) {
  const double cover = coverage(keyframe);
  return cover >= options_.reuse_coverage * keyframe.coverage_at_creation ||
         (replaced && cover >= coverage(*replaced));
}

}  // namespace farfield::terrain
