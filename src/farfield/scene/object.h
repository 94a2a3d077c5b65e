// Object: the unit of visibility, culling and impostor selection (a city block, a building, a tree, a terrain tile).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "farfield/core/bounds.h"
#include "farfield/core/math.h"

namespace farfield::scene {

// One (mesh, material) pair of an object; indices into Scene::meshes and Scene::materials.
struct Part {
  uint32_t mesh = 0;
  uint32_t material = 0;
};

struct Object {
  uint32_t id = 0;  // 1-based; 0 means "background" in item buffers. Scene::addObject assigns index + 1.
  std::string name;
  std::vector<Part> parts;
  Mat4 transform{1.0f};
  Box3 world_bounds;             // kept current by Scene::updateBounds()
  std::vector<Vec2> footprint;   // optional 2D footprint (x, y), counter-clockwise, world metres
  uint32_t parent = 0;           // optional hierarchy: id of the parent group, 0 = root
};

}  // namespace farfield::scene
