// Procedural textures shared by every building of a generated city: a facade tile (one window bay by one floor),
// roof tiles, asphalt for the ground and streets, and dressed stone for the landmarks. Deterministic: the same
// (size, seed) always gives the same pixels, on every platform (integer hashing only, no std distributions).
#pragma once

#include <cstdint>
#include <memory>

#include "farfield/image/image.h"
#include "farfield/scene/scene.h"

namespace farfield::gen {

// Layout of the facade and landmark tiles, in texture coordinates of one tile (glTF convention: v = 0 is the top
// row of the image). Building geometry puts one tile on each window bay and floor (u = metres along the wall / bay
// width, v = metres below the top of the floor / floor height), and at detail >= 2 cuts its window recess exactly
// where the tile paints the window, so the texture's glass lands on the recess.
inline constexpr float kWindowU0 = 0.28f;  // left edge of the window in the tile
inline constexpr float kWindowU1 = 0.72f;  // right edge
inline constexpr float kWindowV0 = 0.22f;  // top edge (below the top of the floor)
inline constexpr float kWindowV1 = 0.78f;  // bottom edge (the sill)

// 8-bit RGBA, size x size pixels (size a power of two, 16..2048; anything else throws farfield::Error).
// Every texture tiles seamlessly (repeat wrap).
image::ColorImage makeFacadeTexture(int size = 256, uint64_t seed = 1);    // plaster, window with frame and glass
image::ColorImage makeRoofTexture(int size = 256, uint64_t seed = 1);      // rows of clay tiles, 1 tile = 4 x 4 m
image::ColorImage makeGroundTexture(int size = 256, uint64_t seed = 1);    // asphalt grain and patches, 8 x 8 m
image::ColorImage makeLandmarkTexture(int size = 256, uint64_t seed = 1);  // stone courses, arched window

// The four textures above at 256x256, built once on first use (thread-safe) and shared by all cities.
struct CityTextures {
  std::shared_ptr<const image::ColorImage> facade;
  std::shared_ptr<const image::ColorImage> roof;
  std::shared_ptr<const image::ColorImage> ground;
  std::shared_ptr<const image::ColorImage> landmark;
};
const CityTextures& cityTextures();

// Material ids of the city palette in a scene (procedural and imported cities look alike).
struct CityMaterials {
  uint32_t ground = 0;      // asphalt
  uint32_t facades[3] = {};  // cream, ochre, grey tints of the facade texture
  uint32_t roof = 0;        // roof tiles
  uint32_t landmark = 0;    // landmark stone
};
// Adds the palette to the scene in that order: asphalt, the three facades, roof tiles, landmark stone.
CityMaterials addCityMaterials(scene::Scene& scene);

}  // namespace farfield::gen
