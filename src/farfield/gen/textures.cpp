// Procedural city textures. Every texture is a function of pixel coordinates and a seed through integer hashing and
// periodic value noise, so it is the same on every platform and tiles seamlessly.
#include "farfield/gen/textures.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "farfield/core/error.h"

namespace farfield::gen {

namespace {

uint32_t hash3(uint32_t x, uint32_t y, uint32_t seed) {
  uint32_t h = x * 0x8da6b343u ^ y * 0xd8163841u ^ seed * 0xcb1ab31fu;
  h ^= h >> 16;
  h *= 0x7feb352du;
  h ^= h >> 15;
  h *= 0x846ca68bu;
  h ^= h >> 16;
  return h;
}

float hashUnit(uint32_t x, uint32_t y, uint32_t seed) { return float(hash3(x, y, seed) >> 8) * (1.0f / 16777216.0f); }

// Value noise on a lattice of `period` cells per texture (wrapping), at texture coordinates (u, v) in [0, 1).
float periodicNoise(float u, float v, int period, uint32_t seed) {
  const float x = u * float(period), y = v * float(period);
  const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
  const float fx = x - float(x0), fy = y - float(y0);
  auto wrap = [period](int i) { return uint32_t(((i % period) + period) % period); };
  auto smooth = [](float t) { return t * t * (3.0f - 2.0f * t); };
  const float a = hashUnit(wrap(x0), wrap(y0), seed), b = hashUnit(wrap(x0 + 1), wrap(y0), seed);
  const float c = hashUnit(wrap(x0), wrap(y0 + 1), seed), d = hashUnit(wrap(x0 + 1), wrap(y0 + 1), seed);
  const float sx = smooth(fx), sy = smooth(fy);
  return (a + (b - a) * sx) + ((c + (d - c) * sx) - (a + (b - a) * sx)) * sy;
}

// Fractal sum of periodic noise octaves, about [0, 1].
float fbm(float u, float v, int period, int octaves, uint32_t seed) {
  float sum = 0.0f, amp = 0.5f, norm = 0.0f;
  for (int o = 0; o < octaves; ++o) {
    sum += amp * periodicNoise(u, v, period << o, seed + uint32_t(o) * 101u);
    norm += amp;
    amp *= 0.5f;
  }
  return sum / norm;
}

image::Rgba8 toPixel(const Vec3& c) {
  auto q = [](float x) { return uint8_t(std::lround(std::clamp(x, 0.0f, 1.0f) * 255.0f)); };
  return image::Rgba8(q(c.r), q(c.g), q(c.b), 255);
}

void checkSize(int size, const char* what) {
  if (size < 16 || size > 2048 || (size & (size - 1)) != 0)
    throw Error(std::string(what) + " texture",
                "size " + std::to_string(size) + ": expected a power of two from 16 to 2048");
}

template <class F>
image::ColorImage paint(int size, F&& colour) {
  image::ColorImage img(size, size);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const float u = (float(x) + 0.5f) / float(size), v = (float(y) + 0.5f) / float(size);
      img.at(x, y) = toPixel(colour(u, v, x, y));
    }
  return img;
}

}  // namespace

image::ColorImage makeFacadeTexture(int size, uint64_t seed) {
  checkSize(size, "facade");
  const uint32_t s = uint32_t(seed * 2654435761u);
  const Vec3 plaster(0.86f, 0.82f, 0.74f), frame(0.93f, 0.92f, 0.88f), glass_top(0.32f, 0.40f, 0.48f),
      glass_bottom(0.12f, 0.15f, 0.20f);
  const float fw = 0.03f;  // frame width in tile units
  return paint(size, [&](float u, float v, int, int) {
    const float grain = fbm(u, v, 8, 4, s) - 0.5f;
    Vec3 c = plaster * (1.0f + 0.18f * grain);
    // A string course at the floor line (top of the tile) and a darker plinth line at its bottom.
    if (v < 0.035f) c *= 0.86f;
    if (v > 0.975f) c *= 0.92f;
    const bool in_frame = u > kWindowU0 - fw && u < kWindowU1 + fw && v > kWindowV0 - fw && v < kWindowV1 + fw;
    const bool in_glass = u > kWindowU0 && u < kWindowU1 && v > kWindowV0 && v < kWindowV1;
    if (in_glass) {
      const float t = (v - kWindowV0) / (kWindowV1 - kWindowV0);
      c = glass_top + (glass_bottom - glass_top) * t;
      // A diagonal sky reflection and a mullion cross.
      const float diag = (u - kWindowU0) + 0.6f * (v - kWindowV0);
      if (diag > 0.18f && diag < 0.27f) c += Vec3(0.10f, 0.11f, 0.12f);
      const float um = 0.5f * (kWindowU0 + kWindowU1), vm = kWindowV0 + 0.38f * (kWindowV1 - kWindowV0);
      if (std::abs(u - um) < 0.012f || std::abs(v - vm) < 0.012f) c = frame * 0.9f;
    } else if (in_frame) {
      c = frame * (1.0f + 0.05f * grain);
    } else if (v > kWindowV1 + fw && v < kWindowV1 + fw + 0.05f && u > kWindowU0 - 2 * fw && u < kWindowU1 + 2 * fw) {
      c *= 0.7f;  // shadow under the sill
    }
    return c;
  });
}

image::ColorImage makeRoofTexture(int size, uint64_t seed) {
  checkSize(size, "roof");
  const uint32_t s = uint32_t(seed * 2246822519u + 7u);
  const int rows = 8, cols = 8;
  const Vec3 clay(0.62f, 0.30f, 0.20f);
  return paint(size, [&](float u, float v, int, int) {
    const int row = std::min(rows - 1, int(v * rows));
    const float fv = v * rows - float(row);
    // Alternate rows shift by half a tile.
    const float us = u * cols + ((row & 1) ? 0.5f : 0.0f);
    const int col = int(std::floor(us)) % cols;
    const float fu = us - std::floor(us);
    const float tile_var = 0.85f + 0.3f * hashUnit(uint32_t(col), uint32_t(row), s);
    Vec3 c = clay * tile_var * (0.9f + 0.2f * fbm(u, v, 16, 3, s + 3u));
    c *= 0.75f + 0.35f * fv;  // each tile lit at its lower lip (v grows down the slope)
    if (fu < 0.04f || fu > 0.96f) c *= 0.6f;
    if (fv > 0.93f) c *= 0.55f;  // shadow line under the overlapping row
    return c;
  });
}

image::ColorImage makeGroundTexture(int size, uint64_t seed) {
  checkSize(size, "ground");
  const uint32_t s = uint32_t(seed * 3266489917u + 11u);
  return paint(size, [&](float u, float v, int x, int y) {
    const float patches = fbm(u, v, 4, 3, s);
    const float grain = hashUnit(uint32_t(x), uint32_t(y), s + 5u);
    float g = 0.26f + 0.08f * (patches - 0.5f) + 0.07f * (grain - 0.5f);
    if (grain > 0.985f) g += 0.12f;  // light stone chips
    return Vec3(g, g, g * 1.03f);
  });
}

image::ColorImage makeLandmarkTexture(int size, uint64_t seed) {
  checkSize(size, "landmark");
  const uint32_t s = uint32_t(seed * 668265263u + 13u);
  const Vec3 stone(0.80f, 0.77f, 0.70f), mortar(0.58f, 0.55f, 0.50f), glass(0.16f, 0.18f, 0.24f);
  const int courses = 6;
  return paint(size, [&](float u, float v, int, int) {
    const int course = std::min(courses - 1, int(v * courses));
    const float fv = v * courses - float(course);
    const float us = u * 3.0f + ((course & 1) ? 0.5f : 0.0f);
    const int block = int(std::floor(us)) % 3;
    const float fu = us - std::floor(us);
    Vec3 c = stone * (0.9f + 0.15f * hashUnit(uint32_t(block), uint32_t(course), s)) *
             (0.92f + 0.16f * fbm(u, v, 8, 3, s + 1u));
    if (fv < 0.05f || fu < 0.02f) c = mortar;
    // Arched window: a rectangle topped by a half circle, all inside the shared window rectangle.
    const float cu = 0.5f * (kWindowU0 + kWindowU1), half = 0.5f * (kWindowU1 - kWindowU0);
    const float arch_centre = kWindowV0 + half;
    const bool in_rect = u > kWindowU0 && u < kWindowU1 && v > arch_centre && v < kWindowV1;
    const float du = u - cu, dv = v - arch_centre;
    const bool in_arch = dv <= 0.0f && du * du + dv * dv < half * half;
    if (in_rect || in_arch) {
      c = glass * (1.0f + 0.4f * (kWindowV1 - v));
      if (std::abs(du) < 0.01f) c = mortar;
    }
    return c;
  });
}

const CityTextures& cityTextures() {
  static const CityTextures textures = [] {
    CityTextures t;
    t.facade = std::make_shared<const image::ColorImage>(makeFacadeTexture(256, 1));
    t.roof = std::make_shared<const image::ColorImage>(makeRoofTexture(256, 1));
    t.ground = std::make_shared<const image::ColorImage>(makeGroundTexture(256, 1));
    t.landmark = std::make_shared<const image::ColorImage>(makeLandmarkTexture(256, 1));
    return t;
  }();
  return textures;
}

CityMaterials addCityMaterials(scene::Scene& scene) {
  const CityTextures& tex = cityTextures();
  auto add = [&](const char* name, const Vec4& colour, const std::shared_ptr<const image::ColorImage>& texture) {
    scene::Material m;
    m.name = name;
    m.base_color = colour;
    m.texture = texture;
    return scene.addMaterial(std::move(m));
  };
  CityMaterials ids;
  ids.ground = add("asphalt", Vec4(1.0f), tex.ground);
  ids.facades[0] = add("facade cream", Vec4(1.0f, 0.97f, 0.92f, 1.0f), tex.facade);
  ids.facades[1] = add("facade ochre", Vec4(1.0f, 0.86f, 0.68f, 1.0f), tex.facade);
  ids.facades[2] = add("facade grey", Vec4(0.86f, 0.87f, 0.9f, 1.0f), tex.facade);
  ids.roof = add("roof tiles", Vec4(1.0f), tex.roof);
  ids.landmark = add("landmark stone", Vec4(1.0f), tex.landmark);
  return ids;
}

}  // namespace farfield::gen
