#include "farfield/extract/bake_options.h"

#include <cmath>

#include "farfield/core/error.h"

namespace farfield::extract {

void validateBakeOptions(const BakeOptions& o) {
  if (o.resolution < 8 || o.resolution > 8192)
    throw Error("--resolution", "must be 8..8192 pixels, got " + std::to_string(o.resolution));
  if (!(o.fov_deg > 1.0f && o.fov_deg < 170.0f))
    throw Error("--fov", "must be between 1 and 170 degrees, got " + std::to_string(o.fov_deg));
  if (!std::isfinite(o.eye_height)) throw Error("--eye-height", "must be finite");
  if (!(o.near_plane > 0.0f && o.far_plane > o.near_plane)) throw Error("bake options", "need 0 < near < far");
  if (o.workers < 0) throw Error("--workers", "must be 0 (automatic) or more");
}

Camera cellCamera(const urban::CellMap& cells, uint32_t cell, const BakeOptions& options,
                  const std::function<float(float, float)>& ground) {
  if (cell >= cells.cellCount())
    throw Error("cell " + std::to_string(cell), "no such half-edge (the street graph has " +
                                                    std::to_string(cells.cellCount()) + ")");
  if (cells.degenerate(cell))
    throw Error("cell " + std::to_string(cell), "street too short (" + std::to_string(cells.graph().length(cell)) +
                                                    " m) to place a creation camera along it");
  const Vec2 a = cells.graph().originPosition(cell), b = cells.graph().destinationPosition(cell);
  const Vec3 eye(a, ground(a.x, a.y) + options.eye_height);
  const Vec3 at(b, ground(b.x, b.y) + options.eye_height);
  impostor::DepthMeshOptions o = options.depth_mesh;
  o.resolution = options.resolution;
  o.fov_y = float(degToRad(double(options.fov_deg)));
  return impostor::creationCamera(eye, at, o, options.near_plane, options.far_plane);
}

}  // namespace farfield::extract
