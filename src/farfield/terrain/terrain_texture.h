// The "original texture map" of LOD-sprite (Chen et al. 1999, section 3.1): a colour image over the heightfield,
// from elevation and slope with hill shading baked in (the terrain is drawn unlit, so every technique shows the
// same shading), or a given image.
//
// Texel layout: texel (i, j) of a `scale`-times texture covers the heightfield around world
// ((i + 0.5) / scale * cell_x - 0.5 * cell_x, ...); with scale 1, texel (i, j) is centred on grid point (i, j).
// Image row r is grid row r (row 0 = SOUTH), so flip the image vertically to view it north-up (writeTexturePng
// does). texCoord() gives the uv of a world point under this layout.
#pragma once

#include <string>

#include "farfield/core/math.h"
#include "farfield/image/image.h"
#include "farfield/terrain/heightfield.h"

namespace farfield::terrain {

struct TextureOptions {
  int scale = 1;                              // texels per grid cell along each axis (1..4)
  Vec3 light_direction{-0.5f, 0.6f, -0.62f};  // direction the light travels (from the north-west, down)
  float ambient = 0.45f;
  float rock_slope_deg = 35.0f;  // slopes steeper than this turn to rock: (0, 90]
  // A part of a larger terrain (a paged tile, paged_terrain.h): the heights the elevation ramp spans (ramp_lo >=
  // ramp_hi: the heightfield's own range), and the larger grid's point at the heightfield's (0, 0) and the step
  // between its points, which place the per-texel variation. With the larger terrain's range, step 1 and scale 1,
  // the part's texels are the larger texture's texels at those points.
  float ramp_lo = 0.0f, ramp_hi = 0.0f;
  IVec2 origin{0};
  int step = 1;
  // Every texel through Heightfield::sample's bilinear lookups, as scales above 1 are (scale 1 otherwise reads its
  // grid points directly, several times faster, to the same texels): for checks.
  bool bilinear_lookups = false;
};

image::ColorImage terrainTexture(const Heightfield& hf, const TextureOptions& options = {});

// The texture's share of rock at a surface normal: 0 up to slopes of 0.7 times the rock slope, 1 from 1.3 times,
// linear in the slope (acos of the normal's z) between. Outside that band the normal's z decides it without the
// arccosine, which was a third of a texel's cost (a paged terrain's loading thread makes a page's texels: 90 ms a
// page on the 16,385^2 flight); a z within 1e-4 of a band edge still takes it (1e-4 in z is more than 1e-4 rad of
// slope, where acos's float error is 1e-7), so every share is the arccosine's.
class RockShare {
 public:
  explicit RockShare(float rock_slope_rad);  // rock_slope_rad > 0 (terrainTexture checks its option)
  float operator()(float normal_z) const {
    if (normal_z >= flat_z_) return 0.0f;
    if (normal_z <= steep_z_) return 1.0f;
    return inBand(normal_z);
  }

 private:
  float inBand(float normal_z) const;
  float rock_, flat_z_, steep_z_;
};

// uv of a world (x, y) for a texture of the layout above (any scale): u = (x / cell_x + 0.5) / width.
Vec2 texCoord(const Heightfield& hf, Vec2 world_xy);
// Scale and offset so that uv = world_xy * scale + offset (what the GPU renderer needs).
void texCoordTransform(const Heightfield& hf, Vec2& scale, Vec2& offset);

// A given image as the original texture: read as PNG, row 0 = NORTH as usual for image files (flipped into the
// layout above). Throws farfield::Error for unreadable files.
image::ColorImage loadTexture(const std::string& path);
// Writes the texture north-up.
void writeTexturePng(const std::string& path, const image::ColorImage& texture);

}  // namespace farfield::terrain
