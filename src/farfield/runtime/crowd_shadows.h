// Where the crowd's shadow map looks (Steed's lecture part 3, "Impostors & shadowmaps"; gpu/shadow_map.h): an
// orthographic box along the scene's light, fitted per frame to the receivers the camera sees nearby and to the
// agents that shadow them. Pure geometry, no GL.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/gpu/shadow_map.h"

namespace farfield::runtime {

struct CasterSphere {
  Vec3 centre{0.0f};
  float radius = 0.0f;
};

struct ShadowFit {
  gpu::ShadowProjection projection;
  std::vector<uint32_t> casters;  // indices of the spheres inside the box, increasing
  // Per caster, the pixels (x0, y0, x1, y1; row 0 at the bottom, as GL scissors; exclusive ends) that can hold its
  // shadow on a receiver no lower than `drop_m` below its sphere: the sphere swept along the light down to there,
  // projected (empty ones left out). The whole frame alone when a swept sphere reaches behind the near plane or the
  // light is not downwards.
  std::vector<glm::ivec4> screen_rects;
};

// Receivers: what `camera` sees up to `distance_m` along its view (the frustum cut there). Light space: x, y across
// the light, z along `light_dir` (the direction the light travels). Casters: the spheres whose light-space footprint
// (a disc of their radius: an orthographic shadow never leaves it) overlaps the receivers' light-space bounds. The
// map covers the union of the casters' footprints clipped to those bounds (square texels, map_size per side) and the
// casters' depth range. No caster: an empty list (the projection is then unused). Throws farfield::Error for a
// zero light direction, a non-positive distance or a map under 16 texels.
ShadowFit fitShadow(const Camera& camera, const Vec3& light_dir, std::span<const CasterSphere> spheres,
                    float distance_m, int map_size, float drop_m = 1.0f);

// The map for casters the CPU does not know (the GPU crowd's): the receivers' light-space bounds grown by reach_m on
// every side (casters standing on a receiver reach no farther: the agents' height and radius), and the whole frame as
// the receivers' screen region. No caster list. Throws as fitShadow.
ShadowFit fitShadowReceivers(const Camera& camera, const Vec3& light_dir, float distance_m, int map_size,
                             float reach_m);

}  // namespace farfield::runtime
