// LOD-sprite terrain with a sprite per tile (see tile_sprite_renderer.h).
#include "farfield/terrain/tile_sprite_renderer.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "farfield/core/error.h"
#include "farfield/terrain/lod_sprite.h"
#include "farfield/terrain/tile_sprites.h"
#include "farfield/terrain/sprite_error.h"

namespace farfield::terrain {

struct TileSpriteRenderer::Sprite {
  Camera camera;
  Mat4 view_proj{1.0f};
  GridRect region;
  gpu::RenderTarget target;
  image::DepthImage depth;
  KeyframeVisibility visibility;
  uint64_t last_seen = 0;
  bool view_bound = false;  // took the frame's view: valid while the view has not turned past its margin
  Vec3 key_forward{0.0f};
  // This frame's low-resolution triangles and quadrants of the tile.
  std::vector<uint32_t> triangles;
  std::vector<LodQuadrant> quadrants;
  bool has_keyframe = false;
  bool due = false;             // this frame: no sprite, or its error reached epsilon (or its view turned away)
  uint64_t served = 0;          // frames drawn with the current sprite (its lifetime so far)
  uint64_t keyframe_triangles = 0;  // the current sprite's keyframe
};

namespace {


int roundUp(int v, int m) { return (v + m - 1) / m * m; }

}  // namespace

TileSpriteRenderer::TileSpriteRenderer(const QuadtreeLod& lod, gpu::TerrainRenderer& renderer, int width, int height,
                                       const TileSpriteRenderOptions& options)
    : lod_(lod), renderer_(renderer), width_(width), height_(height), options_(options) {
  if (options.tile_cells < 1) throw Error("lod-sprite-tiles", "tile size must be at least 1 cell");
  if (!(options.epsilon > 0.0)) throw Error("lod-sprite-tiles", "error threshold epsilon must be positive (pixels)");
  if (!(options.high_error > 0.0f) || !(options.low_error >= options.high_error))
    throw Error("lod-sprite-tiles", "need 0 < high-resolution error <= low-resolution error (pixels)");
  if (width < 1 || height < 1) throw Error("lod-sprite-tiles", "frame size must be positive");
  if (!(options.region_margin >= 0.0f && options.region_margin <= 1.0f))
    throw Error("lod-sprite-tiles", "region margin must be 0..1");
  if (!(options.max_half_angle_deg > 1.0f && options.max_half_angle_deg < 89.0f))
    throw Error("lod-sprite-tiles", "the widest half-angle must be between 1 and 89 degrees");
  if (options.max_sprite_size < 16) throw Error("lod-sprite-tiles", "sprites need at least 16 pixels per side");
  if (!(options.view_margin >= 0.0f && options.view_margin <= 1.0f))
    throw Error("lod-sprite-tiles", "view margin must be 0..1 (share of the frame size per side)");
  if (options.keep_frames < 0) throw Error("lod-sprite-tiles", "keep_frames must not be negative");
  if (options.max_carried_high < 0) throw Error("lod-sprite-tiles", "max_carried_high must not be negative");
  tiles_x_ = (lod.width() - 2) / options.tile_cells + 1;
  tiles_y_ = (lod.height() - 2) / options.tile_cells + 1;
  // Height range per tile, over its grid points (borders included).
  tile_min_z_.assign(size_t(tiles_x_) * size_t(tiles_y_), std::numeric_limits<float>::max());
  tile_max_z_.assign(tile_min_z_.size(), std::numeric_limits<float>::lowest());
  const std::vector<Vec3>& positions = lod.positions();
  for (int y = 0; y < lod.height(); ++y)
    for (int x = 0; x < lod.width(); ++x) {
      const float z = positions[size_t(x) + size_t(y) * size_t(lod.width())].z;
      // A border point belongs to the tiles on both sides.
      const int ty0 = std::max(0, (y - 1) / options.tile_cells), ty1 = std::min(tiles_y_ - 1, y / options.tile_cells);
      const int tx0 = std::max(0, (x - 1) / options.tile_cells), tx1 = std::min(tiles_x_ - 1, x / options.tile_cells);
      for (int ty = ty0; ty <= ty1; ++ty)
        for (int tx = tx0; tx <= tx1; ++tx) {
          const size_t t = size_t(tx) + size_t(ty) * size_t(tiles_x_);
          tile_min_z_[t] = std::min(tile_min_z_[t], z);
          tile_max_z_[t] = std::max(tile_max_z_[t], z);
        }
    }
}

TileSpriteRenderer::~TileSpriteRenderer() = default;

IVec2 TileSpriteRenderer::tileOf(int x, int y) const {
  return gridPointTile(x, y, lod_.width(), lod_.height(), options_.tile_cells);
}

void TileSpriteRenderer::reset() {
  for (auto& [key, s] : sprites_) release(*s);
  sprites_.clear();
  counters_ = {};
  frame_ = 0;
  high_triangles_ = low_at_high_ = 0;
  high_known_ = false;
  high_streak_ = carry_high_ = 0;
  lifetimes_.clear();
}

bool TileSpriteRenderer::sprite(IVec2 tile, SpriteView& out) const {
  auto it = sprites_.find({tile.x, tile.y});
  if (it == sprites_.end() || !it->second->has_keyframe) return false;
  out = SpriteView{&it->second->camera, it->second->region, &it->second->depth};
  return true;
}

gpu::RenderTarget TileSpriteRenderer::takeTarget(int width, int height) {
  auto it = spare_.find({width, height});
  if (it != spare_.end()) {
    gpu::RenderTarget t = std::move(it->second.back());
    it->second.pop_back();
    if (it->second.empty()) spare_.erase(it);
    --spare_count_;
    return t;
  }
  return gpu::RenderTarget(width, height);
}

void TileSpriteRenderer::release(Sprite& s) {
  if (s.target.width() > 0) {
    // Sizes vary from sprite to sprite (multiples of 16 pixels), so only a few released targets are kept for reuse:
    // a long flight would otherwise hold one of every size it met.
    if (spare_count_ < kMaxSpareTargets) {
      spare_[{s.target.width(), s.target.height()}].push_back(std::move(s.target));
      ++spare_count_;
    }
    s.target = gpu::RenderTarget();
  }
  s.has_keyframe = false;
}

void TileSpriteRenderer::countFrame(const TileSpriteRenderFrame& info) {
  ++counters_.frames;
  counters_.frames_with_keyframes += info.tiles_refreshed ? 1 : 0;
  counters_.tile_keyframes += info.tiles_refreshed;
  counters_.tile_frames_in_view += info.tiles_in_view;
  counters_.view_framed_keyframes += info.tiles_view_framed;
  counters_.keyframe_triangles += info.keyframe_triangles;
  counters_.low_triangles += info.low_triangles;
  counters_.sprite_triangles += info.sprite_triangles;
  size_t held = 0;
  for (const auto& [key, s] : sprites_) held += s->has_keyframe ? 1 : 0;
  counters_.peak_sprites = std::max(counters_.peak_sprites, held);
  counters_.peak_sprite_bytes = std::max(counters_.peak_sprite_bytes, spriteBytes());
}

bool TileSpriteRenderer::chooseHigh(size_t due, TileSpriteRenderFrame& info) const {
  if (!options_.cost) return false;
  if (!high_known_) return true;  // the high LOD's size is learnt from one high frame first
  const TerrainCost& c = *options_.cost;
  const double high_tris =
      low_at_high_ > 0 ? double(high_triangles_) * double(low_.triangleCount()) / double(low_at_high_)
                       : double(high_triangles_);
  size_t draws = 1;  // the triangles without a sprite
  for (const auto& [key, s] : sprites_) draws += !s->triangles.empty() && (s->has_keyframe || s->due);
  PathCosts p;
  p.high_ms = c.frameMs(high_tris, 1.0, width_, height_);
  p.sprite_ms = c.frameMs(double(low_.triangleCount()), double(draws), width_, height_);
  // Each due tile's keyframe, predicted from the tile's last one (triangles and size; a tile without one: its share
  // of the high LOD at frame size) and amortised over the frames its last sprite served (a tile without one: the
  // median of recent lifetimes): near tiles trip often and far ones seldom, so one lifetime for all would misprice
  // both. The keyframes share the frame's fixed cost (the model's base, paid once).
  const double base_ms = c.frame.base_ms * c.safety_factor;
  const double fallback_life = spriteLifetimeEstimate(lifetimes_, 10.0);
  double keyframes_ms = due > 0 ? base_ms : 0.0, amortised_ms = 0.0;
  for (const auto& [key, s] : sprites_) {
    if (s->triangles.empty() || !s->due) continue;
    const int kw = s->has_keyframe ? s->camera.width : width_, kh = s->has_keyframe ? s->camera.height : height_;
    const double tris = s->has_keyframe ? double(s->keyframe_triangles)
                                        : high_tris * double(s->triangles.size() / 3) /
                                              double(std::max<size_t>(low_.triangleCount(), 1));
    const double k = c.frameMs(tris, 1.0, kw, kh) - base_ms + c.readbackMs(kw, kh);
    keyframes_ms += k;
    amortised_ms += k / (s->has_keyframe ? double(std::max<uint64_t>(s->served, 1)) : fallback_life);
  }
  if (due > 0) amortised_ms += base_ms / fallback_life;
  p.keyframe_ms = p.sprite_ms + keyframes_ms;
  info.predicted_high_ms = p.high_ms;
  info.predicted_sprite_ms = p.sprite_ms;
  info.predicted_keyframe_ms = p.keyframe_ms;
  // path_choice.h's rule, each keyframe over its own expected lifetime: the tiles when their frame plus the
  // keyframes' share per frame of their lives costs less than the high LOD.
  return p.sprite_ms + amortised_ms >= p.high_ms;
}

gpu::FrameStats TileSpriteRenderer::drawHigh(const Camera& camera, gpu::RenderTarget& target,
                                             TileSpriteRenderFrame& info) {
  gpu::FrameStats stats;
  info.path = TerrainPath::High;
  gpu::addDraw(stats, renderLodFrame(lod_, renderer_, camera, LodSettings{options_.high_error, true, false}, target,
                                     high_));
  info.high_triangles = high_.triangleCount();
  info.max_tile_error_px = 0.0;
  ++counters_.high_frames;
  if (info.carried) {
    ++counters_.carried_high_frames;
  } else {
    // The next run of frames drawn without deciding: 1, 2, 4, ... up to max_carried_high for each choice of the high
    // LOD in a row (not for the first frame, drawn to learn the high LOD's size). Then that size beside this frame's
    // low mesh (the choice scales one by the other).
    if (high_known_) {
      high_streak_ = std::min(high_streak_ + 1, 30);
      carry_high_ = std::min(options_.max_carried_high, 1 << (high_streak_ - 1));
    }
    high_triangles_ = high_.triangleCount();
    low_at_high_ = low_.triangleCount();
    high_known_ = true;
  }
  countFrame(info);
  return stats;
}

uint64_t TileSpriteRenderer::spriteBytes() const {
  uint64_t bytes = 0;
  // RGBA8 colour, 32-bit ids, 32-bit float depth on the GPU, and the float z-buffer copy.
  for (const auto& [key, s] : sprites_)
    if (s->has_keyframe) bytes += uint64_t(s->target.width()) * uint64_t(s->target.height()) * 16;
  return bytes;
}

bool TileSpriteRenderer::frame(const Camera& camera, GridRect r, Camera& out) const {
  // The region's box: its grid rectangle and the height range of the tiles it touches.
  const IVec2 t0 = tileOf(r.x0, r.y0), t1 = tileOf(r.x1, r.y1);
  float z0 = std::numeric_limits<float>::max(), z1 = std::numeric_limits<float>::lowest();
  for (int ty = t0.y; ty <= t1.y; ++ty)
    for (int tx = t0.x; tx <= t1.x; ++tx) {
      z0 = std::min(z0, tile_min_z_[size_t(tx) + size_t(ty) * size_t(tiles_x_)]);
      z1 = std::max(z1, tile_max_z_[size_t(tx) + size_t(ty) * size_t(tiles_x_)]);
    }
  const Vec3 lo = lod_.position(uint32_t(r.x0) + uint32_t(r.y0) * uint32_t(lod_.width()));
  const Vec3 hi = lod_.position(uint32_t(r.x1) + uint32_t(r.y1) * uint32_t(lod_.width()));
  const Vec3 box_lo(std::min(lo.x, hi.x), std::min(lo.y, hi.y), z0);
  const Vec3 box_hi(std::max(lo.x, hi.x), std::max(lo.y, hi.y), z1);
  const Vec3 centre = 0.5f * (box_lo + box_hi);
  const Vec3 f = glm::normalize(centre - camera.eye);
  if (!(glm::length(centre - camera.eye) > 0.0f)) return false;
  const Vec3 up = std::abs(f.z) < 0.95f ? Vec3(0.0f, 0.0f, 1.0f) : Vec3(0.0f, 1.0f, 0.0f);
  const Vec3 right = glm::normalize(glm::cross(f, up));
  const Vec3 u = glm::cross(right, f);
  const float max_tan = std::tan(float(degToRad(double(options_.max_half_angle_deg))));
  float tx = 0.0f, ty = 0.0f;
  for (int k = 0; k < 8; ++k) {
    const Vec3 corner((k & 1) ? box_hi.x : box_lo.x, (k & 2) ? box_hi.y : box_lo.y, (k & 4) ? box_hi.z : box_lo.z);
    const Vec3 d = corner - camera.eye;
    const float z = glm::dot(d, f);
    if (!(z > 2.0f * camera.near_plane)) return false;
    tx = std::max(tx, std::abs(glm::dot(d, right)) / z);
    ty = std::max(ty, std::abs(glm::dot(d, u)) / z);
    if (tx > max_tan || ty > max_tan) return false;
  }
  // The frame's pixel density (pixels per unit of tangent at the image centre), capped by the largest sprite.
  const double density = QuadtreeLod::pixelsPerRadian(camera);
  const int w = std::clamp(roundUp(int(std::ceil(2.0 * tx * density)), 16), 16, options_.max_sprite_size);
  const int h = std::clamp(roundUp(int(std::ceil(2.0 * ty * density)), 16), 16, options_.max_sprite_size);
  const double fit = std::min(double(w) / (2.0 * std::max(tx, 1e-6f)), double(h) / (2.0 * std::max(ty, 1e-6f)));
  out = camera;
  out.at = centre;
  out.up = up;
  out.width = w;
  out.height = h;
  out.fov_y = float(2.0 * std::atan(double(h) / (2.0 * fit)));
  return true;
}

void TileSpriteRenderer::renderKeyframe(Sprite& s, TileSpriteRenderFrame& info, gpu::FrameStats& stats) {
  // The high-resolution LOD of the region's blocks, seen from the keyframe camera; the triangles meeting the region.
  const int block = lod_.block();
  const GridRect& r = s.region;
  const LodWindow window{r.x0 / block, r.y0 / block, std::min(lod_.blocksX(), (std::max(r.x1, 1) - 1) / block + 1),
                         std::min(lod_.blocksY(), (std::max(r.y1, 1) - 1) / block + 1), uint32_t(lod_.width())};
  lod_.build(s.camera, LodSettings{options_.high_error, true, false}, high_, &window);
  keyframe_indices_.clear();
  const uint32_t w = uint32_t(lod_.width());
  for (size_t t = 0; t < high_.indices.size(); t += 3) {
    int x0 = std::numeric_limits<int>::max(), y0 = x0, x1 = -1, y1 = -1;
    for (size_t k = 0; k < 3; ++k) {
      const int x = int(high_.indices[t + k] % w), y = int(high_.indices[t + k] / w);
      x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
    }
    if (x1 < r.x0 || x0 > r.x1 || y1 < r.y0 || y0 > r.y1) continue;
    keyframe_indices_.insert(keyframe_indices_.end(), high_.indices.begin() + std::ptrdiff_t(t),
                             high_.indices.begin() + std::ptrdiff_t(t + 3));
  }
  if (s.target.width() != s.camera.width || s.target.height() != s.camera.height) {
    release(s);
    s.target = takeTarget(s.camera.width, s.camera.height);
  }
  s.view_proj = s.camera.viewProjection();
  renderer_.setIndices(keyframe_indices_, 1);
  s.target.clear(options_.sky_color);
  const size_t n = keyframe_indices_.size() / 3;
  gpu::addDraw(stats, renderer_.drawTextured(s.camera, s.target, 0, n, 1));
  s.depth = s.target.readDepth();
  s.visibility.reset(lod_, s.camera, &s.depth, options_.visibility, &s.region);
  if (s.has_keyframe) {
    lifetimes_.push_back(std::max<uint64_t>(s.served, 1));
    while (lifetimes_.size() > 32) lifetimes_.pop_front();
  }
  s.has_keyframe = true;
  s.served = 0;
  s.keyframe_triangles = n;
  info.keyframe_triangles += n;
  info.keyframe_pixels += uint64_t(s.camera.width) * uint64_t(s.camera.height);
  ++info.tiles_refreshed;
}

gpu::FrameStats TileSpriteRenderer::render(const Camera& camera, gpu::RenderTarget& target,
                                           TileSpriteRenderFrame* out) {
  if (camera.width != width_ || camera.height != height_)
    throw Error("lod-sprite-tiles", "camera size differs from the renderer's frame size");
  ++frame_;
  TileSpriteRenderFrame info;
  if (carry_high_ > 0) {
    --carry_high_;
    info.carried = true;
    const gpu::FrameStats stats = drawHigh(camera, target, info);
    if (out) *out = info;
    return stats;
  }
  gpu::FrameStats stats;
  lod_.build(camera, LodSettings{options_.low_error, true, true}, low_);
  info.low_triangles = low_.triangleCount();

  // Triangles and quadrants by tile.
  for (auto& [key, s] : sprites_) {
    s->triangles.clear();
    s->quadrants.clear();
  }
  const uint32_t w = uint32_t(lod_.width());
  auto spriteOf = [&](IVec2 t) -> Sprite& {
    std::unique_ptr<Sprite>& s = sprites_[{t.x, t.y}];
    if (!s) s = std::make_unique<Sprite>();
    return *s;
  };
  for (size_t t = 0; t < low_.indices.size(); t += 3) {
    const IVec2 c = centroidPoint(&low_.indices[t], w);
    Sprite& s = spriteOf(tileOf(c.x, c.y));
    s.triangles.insert(s.triangles.end(), low_.indices.begin() + std::ptrdiff_t(t),
                       low_.indices.begin() + std::ptrdiff_t(t + 3));
  }
  for (const LodQuadrant& q : low_.quadrants) {
    const IVec2 t = tileOf(int(q.centre % w), int(q.centre / w));
    auto it = sprites_.find({t.x, t.y});
    if (it != sprites_.end()) it->second->quadrants.push_back(q);
  }

  // Per tile: which sprites are due (missing, over epsilon, or of a view the frame has turned away from).
  const double beta = pixelAngle(camera);
  size_t due_count = 0;
  for (auto it = sprites_.begin(); it != sprites_.end();) {
    Sprite& s = *it->second;
    if (s.triangles.empty()) {
      if (frame_ - s.last_seen > uint64_t(options_.keep_frames) || !s.has_keyframe) {
        release(s);
        it = sprites_.erase(it);
      } else {
        ++it;
      }
      continue;
    }
    ++info.tiles_in_view;
    s.last_seen = frame_;
    s.due = !s.has_keyframe;
    if (!s.due && s.view_bound)
      s.due = glm::dot(camera.forward(), s.key_forward) < std::cos(options_.view_margin * camera.fov_y);
    if (!s.due) {
      const SpriteError e = spriteError(lod_, s.quadrants, s.camera.eye, camera.eye);
      s.due = keyframeDue(e, beta, options_.epsilon);
      if (!s.due) info.max_tile_error_px = std::max(info.max_tile_error_px, e.pixels(beta));
    }
    due_count += s.due;
    ++it;
  }
  info.tiles_due = due_count;

  // The per-frame choice: the high LOD when the tiles do not pay.
  if (chooseHigh(due_count, info)) {
    gpu::addDraw(stats, drawHigh(camera, target, info));
    if (out) *out = info;
    return stats;
  }
  high_streak_ = 0;

  // The tile path: refresh the tiles due, then draw every tile with its sprite or without.
  frame_indices_.clear();
  struct Range {
    const Sprite* sprite;
    size_t first, count;
  };
  std::vector<Range> ranges;
  std::vector<uint32_t> textured;
  for (auto& [key, sp] : sprites_) {
    Sprite& s = *sp;
    if (s.triangles.empty()) continue;
    if (s.due) {
      // The whole tile (parts out of view now may come into view later) and the triangles reaching past it.
      const IVec2 tile(key.first, key.second);
      GridRect r{tile.x * options_.tile_cells, tile.y * options_.tile_cells,
                 std::min(lod_.width() - 1, (tile.x + 1) * options_.tile_cells),
                 std::min(lod_.height() - 1, (tile.y + 1) * options_.tile_cells)};
      for (uint32_t v : s.triangles) {
        const int x = int(v % w), y = int(v / w);
        r.x0 = std::min(r.x0, x), r.x1 = std::max(r.x1, x), r.y0 = std::min(r.y0, y), r.y1 = std::max(r.y1, y);
      }
      const int gx = std::max(1, int(std::lround(options_.region_margin * float(r.x1 - r.x0))));
      const int gy = std::max(1, int(std::lround(options_.region_margin * float(r.y1 - r.y0))));
      r = GridRect{std::max(0, r.x0 - gx), std::max(0, r.y0 - gy), std::min(lod_.width() - 1, r.x1 + gx),
                   std::min(lod_.height() - 1, r.y1 + gy)};
      s.view_bound = !frame(camera, r, s.camera);
      if (s.view_bound) {
        s.camera = guardBandCamera(camera, width_, height_, options_.view_margin);
        ++info.tiles_view_framed;
      }
      s.key_forward = camera.forward();
      s.region = r;
      renderKeyframe(s, info, stats);
    }
    if (s.has_keyframe) {
      ++s.served;
      // Visible triangles with the sprite, the others with the original texture.
      const size_t first = frame_indices_.size() / 3;
      for (size_t t = 0; t < s.triangles.size(); t += 3) {
        const uint32_t a = s.triangles[t], b = s.triangles[t + 1], c = s.triangles[t + 2];
        std::vector<uint32_t>& to = s.visibility.triangleVisible(a, b, c) ? frame_indices_ : textured;
        to.push_back(a), to.push_back(b), to.push_back(c);
      }
      const size_t count = frame_indices_.size() / 3 - first;
      if (count) ranges.push_back(Range{&s, first, count});
    } else {
      textured.insert(textured.end(), s.triangles.begin(), s.triangles.end());
    }
  }
  info.sprite_triangles = frame_indices_.size() / 3;
  const size_t rest_first = frame_indices_.size() / 3;
  frame_indices_.insert(frame_indices_.end(), textured.begin(), textured.end());
  renderer_.setIndices(frame_indices_, 0);
  for (const Range& r : ranges)
    gpu::addDraw(stats, renderer_.drawSprite(camera, target, r.sprite->target.colorTexture(), r.sprite->view_proj,
                                             r.first, r.count, 0));
  if (!textured.empty())
    gpu::addDraw(stats, renderer_.drawTextured(camera, target, rest_first, textured.size() / 3, 0));

  countFrame(info);
  if (out) *out = info;
  return stats;
}

}  // namespace farfield::terrain
