// Camera paths: street walks along the street graph, fly-overs, orbits. Saved as JSON, one entry per frame.
//
// JSON shape: {"kind": "street", "fps": 30, "frames": [{"eye": [x,y,z], "at": [x,y,z], "up": [x,y,z],
//              "fov_deg": 60}, ...]}
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "farfield/core/bounds.h"
#include "farfield/core/camera.h"
#include "farfield/core/math.h"

namespace farfield::urban {
class StreetGraph;
}

namespace farfield::gen {

struct PathFrame {
  Vec3 eye{0.0f};
  Vec3 at{0.0f, 1.0f, 0.0f};
  Vec3 up{0.0f, 0.0f, 1.0f};
  float fov_y = float(degToRad(60.0));  // vertical, radians
};

struct CameraPath {
  std::string kind;  // "street", "flyover", "orbit", or free text
  float fps = 30.0f;
  std::vector<PathFrame> frames;

  // The camera of frame i at the given image size (near/far planes from the defaults of Camera unless given).
  Camera camera(size_t i, int width, int height, float near_plane = 0.5f, float far_plane = 20000.0f) const;
};

// Throws farfield::Error naming the file (missing, not JSON, missing keys, non-finite numbers, no frames).
CameraPath loadCameraPath(const std::string& path);
void saveCameraPath(const CameraPath& path, const std::string& file);
// The view space around a path (a district along a route): the bounds of its eyes grown by margin_m (>= 0) on the
// ground plane; in height from the lowest to the highest eye, at least 0.5 m tall. Throws farfield::Error naming
// `where` for a path without frames or a negative margin.
Box3 eyeBounds(const CameraPath& path, float margin_m, const std::string& where);

enum class Walker { Pedestrian, Car };  // eye 1.7 m at 1.4 m/s, or 1.2 m at 10 m/s

struct StreetWalkOptions {
  int frames = 600;
  uint64_t seed = 1;
  Walker walker = Walker::Pedestrian;
  float fps = 30.0f;
  float fov_deg = 60.0f;
  float turn_radius = 6.0f;  // metres: smooth turns at junctions
  // Ground height z at (x, y) for terrain under the streets (a hill); null means flat ground at z = 0.
  std::function<float(float x, float y)> ground_height;
};

// A walk along the street graph: starts on a random edge, at each junction takes a random (seeded) next edge,
// avoiding U-turns where possible; stays on the street (inside its width), never inside a block.
CameraPath streetWalk(const urban::StreetGraph& graph, const StreetWalkOptions& options);

struct FlyoverOptions {
  int frames = 600;
  float fps = 30.0f;
  float altitude = 150.0f;  // metres above the scene's ground
  float fov_deg = 60.0f;
};
// Straight line across the given bounds (diagonal), looking ahead and down.
CameraPath flyover(const Box3& bounds, const FlyoverOptions& options);

struct OrbitOptions {
  int frames = 600;
  float fps = 30.0f;
  float radius_scale = 1.2f;   // radius = scale * half the diagonal of the bounds
  float elevation_deg = 25.0f;
  float fov_deg = 50.0f;
};
CameraPath orbit(const Box3& bounds, const OrbitOptions& options);

}  // namespace farfield::gen
