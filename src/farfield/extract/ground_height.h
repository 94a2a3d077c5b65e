// Ground height under a point, from the triangles of given objects (the ground of a city), for placing impostor
// creation cameras at the walker's eye height on hilly ground.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "farfield/core/bounds.h"
#include "farfield/core/math.h"
#include "farfield/scene/scene.h"

namespace farfield::extract {

class GroundHeight {
 public:
  // Collects the upward-facing triangles (normal z > 0.2) of the listed objects (world space) into a grid.
  GroundHeight(const scene::Scene& scene, std::span<const uint32_t> object_ids);

  // The lowest upward-facing surface of those objects above or below (x, y) (the lowest, so that a bridge or roof
  // over the street does not lift the walker); `fallback` where none covers the point.
  float at(float x, float y, float fallback = 0.0f) const;
  size_t triangleCount() const { return triangles_.size(); }

 private:
  struct Triangle {
    Vec3 a, b, c;
  };
  int cellX(float x) const;
  int cellY(float y) const;

  std::vector<Triangle> triangles_;
  Box2 box_;
  float cell_ = 1.0f;
  int nx_ = 0, ny_ = 0;
  std::vector<uint32_t> start_;  // per grid cell, offset into items_ (nx * ny + 1)
  std::vector<uint32_t> items_;  // triangle indices
};

}  // namespace farfield::extract
