// Shadows of agents through a shadow map (Steed's lecture part 3, "Impostors & shadowmaps"): the agents, skinned
// geometry and impostors alike, cast into one depth map from the scene's directional light in a single pass; the
// city and the ground receive, in a screen pass over the frame's depth; agents do not receive (no self-shadowing,
// as in the lecture). The light projection is orthographic (runtime/crowd_shadows.h fits it).
#pragma once

#include <cstdint>
#include <span>

#include "farfield/core/camera.h"
#include "farfield/gpu/program.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/renderer.h"

namespace farfield::gpu {

// Light-space projection of a shadow map: world -> clip with x, y in [-1, 1] across the map and depth z in [0, 1]
// growing away from the light over depth_range_m metres.
struct ShadowProjection {
  Mat4 view_proj{1.0f};
  float depth_range_m = 1.0f;
  float texel_m = 0.0f;  // metres per map texel (the larger side)
};

// A square depth map (32-bit float) with its framebuffer.
class ShadowMap {
 public:
  explicit ShadowMap(int size = 2048);  // needs a current context; throws farfield::Error beyond the GL limit
  ~ShadowMap();
  ShadowMap(const ShadowMap&) = delete;
  ShadowMap& operator=(const ShadowMap&) = delete;
  int size() const { return size_; }
  size_t byteSize() const { return size_t(size_) * size_t(size_) * 4; }
  // Binds the map for casters: viewport = the map, no colour, depth test LESS with writes, no face culling, and
  // clears it to 1 (no caster).
  void bindForCasters() const;
  uint32_t depthTexture() const { return depth_; }

 private:
  int size_ = 0;
  uint32_t depth_ = 0, fbo_ = 0;
};

// The receivers' pass.
class ShadowReceiver {
 public:
  ShadowReceiver();  // needs a current context
  ~ShadowReceiver();
  ShadowReceiver(const ShadowReceiver&) = delete;
  ShadowReceiver& operator=(const ShadowReceiver&) = delete;

  // Darkens the colour of `target` (drawn with `camera`) where the map shadows a receiver: every pixel with depth
  // (not sky) within max_distance_m along the view whose object id has none of `agent_id_mask`'s bits. A receiver at light depth z is shadowed by a map
  // texel holding less than z - bias_m (metres, over the projection's depth range); the share s of the 4x4 texels
  // around it that leave it lit weighs the colour's factor mix(ambient / (ambient + light_color * max(n . -l, 0)),
  // 1, s) per channel: what the renderer's lighting (mesh.frag.glsl) gives without the direct term, n being the
  // surface normal rebuilt from the depth buffer. Only within `regions` (x0, y0, x1, y1 from the bottom left,
  // exclusive ends; they may overlap): the pass shades the kTile-pixel tiles they touch, each pixel once
  // (tileCover). Leaves the target unbound.
  void apply(const Camera& camera, const ShadowMap& map, const ShadowProjection& projection,
             const RenderTarget& target, const LightSettings& light, uint32_t agent_id_mask, float bias_m,
             float max_distance_m, std::span<const glm::ivec4> regions);
  static constexpr int kTile = 16;

 private:
  Program program_;
  uint32_t fbo_ = 0, vao_ = 0, vbo_ = 0;
};

}  // namespace farfield::gpu
