#include "farfield/terrain/terrain_texture.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "farfield/core/error.h"
#include "farfield/image/png_io.h"

namespace farfield::terrain {
namespace {

// Elevation ramp (normalised height 0..1): lowland green, dry grass, brown foothills, grey rock, snow.
Vec3 elevationColor(float t) {
  struct Stop {
    float t;
    Vec3 c;
  };
  static const Stop stops[] = {{0.00f, {0.28f, 0.45f, 0.22f}}, {0.25f, {0.52f, 0.58f, 0.30f}},
                               {0.50f, {0.60f, 0.50f, 0.34f}}, {0.75f, {0.55f, 0.52f, 0.50f}},
                               {0.92f, {0.80f, 0.80f, 0.82f}}, {1.00f, {0.96f, 0.96f, 0.98f}}};
  t = std::clamp(t, 0.0f, 1.0f);
  for (size_t k = 1; k < std::size(stops); ++k)
    if (t <= stops[k].t) {
      const float s = (t - stops[k - 1].t) / (stops[k].t - stops[k - 1].t);
      return glm::mix(stops[k - 1].c, stops[k].c, s);
    }
  return stops[std::size(stops) - 1].c;
}

// Cheap deterministic per-texel variation so that flat areas carry some texture detail the sprite can show.
float hashNoise(int i, int j) {
  uint32_t h = uint32_t(i) * 73856093u ^ uint32_t(j) * 19349663u;
  h = (h ^ (h >> 13)) * 1274126177u;
  return float(h & 0xffffu) / 65535.0f;
}

}  // namespace

RockShare::RockShare(float rock_slope_rad)
    : rock_(rock_slope_rad),
      flat_z_(std::cos(rock_slope_rad * 0.7f) + 1e-4f),
      steep_z_(std::cos(rock_slope_rad * 1.3f) - 1e-4f) {}

float RockShare::inBand(float nz) const {
  const float slope = std::acos(std::clamp(nz, -1.0f, 1.0f));
  return std::clamp((slope - rock_ * 0.7f) / (rock_ * 0.6f), 0.0f, 1.0f);
}

image::ColorImage terrainTexture(const Heightfield& hf, const TextureOptions& o) {
  if (hf.width < 2 || hf.height < 2) throw Error(hf.source, "heightfield too small for a texture");
  if (o.scale < 1 || o.scale > 4) throw Error("texture scale", "must be 1..4");
  if (o.step < 1) throw Error("texture step", "must be 1 or more");
  if (!(o.rock_slope_deg > 0.0f && o.rock_slope_deg <= 90.0f))
    throw Error("texture rock slope", "must be in (0, 90] degrees, got " + std::to_string(o.rock_slope_deg));
  const int tw = hf.width * o.scale, th = hf.height * o.scale;
  image::ColorImage tex(tw, th);
  const bool own_range = !(o.ramp_lo < o.ramp_hi);
  const float lo = own_range ? hf.minHeight() : o.ramp_lo, hi = own_range ? hf.maxHeight() : o.ramp_hi;
  const float span = hi > lo ? hi - lo : 1.0f;
  const Vec3 to_light = -glm::normalize(o.light_direction);
  const float rock = float(degToRad(o.rock_slope_deg));
  const double dx = 0.5 * hf.cell_x, dy = 0.5 * hf.cell_y;
  const RockShare rock_share(rock);
  // lround of a channel in [0, 1] x 255 (a tenth of a texel's cost through libm): x + 0.5 is exact in double for a
  // float x, and truncation is floor there.
  auto byte = [](float x) { return uint8_t(int(double(x * 255) + 0.5)); };
  // The texel's colour from its height and the slopes of the bilinear surface there (central differences of half
  // a cell).
  auto shade = [&](int tx, int ty, float z, float zx, float zy) {
    const Vec3 n = glm::normalize(Vec3(-zx, -zy, 1.0f));
    Vec3 c = elevationColor((z - lo) / span +
                            0.04f * (hashNoise(o.origin.x * o.scale + tx * o.step, o.origin.y * o.scale + ty * o.step) -
                                     0.5f));
    c = glm::mix(c, Vec3(0.47f, 0.44f, 0.42f), rock_share(n.z));
    const float light = o.ambient + (1.0f - o.ambient) * std::max(glm::dot(n, to_light), 0.0f);
    c *= light * 1.15f;
    c = glm::clamp(c, Vec3(0.0f), Vec3(1.0f));
    tex.at(tx, ty) = image::Rgba8(byte(c.r), byte(c.g), byte(c.b), 255);
  };
  if (o.scale == 1 && !o.bilinear_lookups) {
    // Texel centres on grid points: the surface half a cell away is the mean of two neighbours (the point itself
    // at the grid's edge, where the bilinear sample clamps), as Heightfield::sample gives it, without its lookups.
    auto half = [&](int i, int j, int di, int dj) {
      const int ni = i + di, nj = j + dj;
      if (ni < 0 || nj < 0 || ni >= hf.width || nj >= hf.height) return hf.at(i, j);
      return float((double(hf.at(i, j)) + double(hf.at(ni, nj))) * 0.5);
    };
    for (int j = 0; j < th; ++j)
      for (int i = 0; i < tw; ++i)
        shade(i, j, hf.at(i, j), (half(i, j, 1, 0) - half(i, j, -1, 0)) / float(2 * dx),
              (half(i, j, 0, 1) - half(i, j, 0, -1)) / float(2 * dy));
    return tex;
  }
  for (int ty = 0; ty < th; ++ty)
    for (int tx = 0; tx < tw; ++tx) {
      // Grid position of the texel centre.
      const double gx = (tx + 0.5) / o.scale - 0.5, gy = (ty + 0.5) / o.scale - 0.5;
      const double x = std::clamp(gx, 0.0, double(hf.width - 1)) * hf.cell_x;
      const double y = std::clamp(gy, 0.0, double(hf.height - 1)) * hf.cell_y;
      shade(tx, ty, hf.sample(x, y), (hf.sample(x + dx, y) - hf.sample(x - dx, y)) / float(2 * dx),
            (hf.sample(x, y + dy) - hf.sample(x, y - dy)) / float(2 * dy));
    }
  return tex;
}

Vec2 texCoord(const Heightfield& hf, Vec2 world_xy) {
  Vec2 scale, offset;
  texCoordTransform(hf, scale, offset);
  return world_xy * scale + offset;
}

void texCoordTransform(const Heightfield& hf, Vec2& scale, Vec2& offset) {
  // Independent of the texture's scale factor: grid point i sits at texel position (i + 0.5) * s of s * width.
  scale = Vec2(float(1.0 / (hf.cell_x * hf.width)), float(1.0 / (hf.cell_y * hf.height)));
  offset = Vec2(float(0.5 / hf.width), float(0.5 / hf.height));
}

image::ColorImage loadTexture(const std::string& path) {
  image::ColorImage img = image::readPng(path);
  img.flipVertically();
  return img;
}

void writeTexturePng(const std::string& path, const image::ColorImage& texture) {
  image::ColorImage img = texture;
  img.flipVertically();
  image::writePng(path, img);
}

}  // namespace farfield::terrain
