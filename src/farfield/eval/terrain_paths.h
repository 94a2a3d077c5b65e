// Camera paths for the terrain experiments (Chen et al. 1999, Figure 8): flythrough viewpoints as a camera path,
// the same path at another frame count (Figure 12's sweep), and clip planes that hold the whole terrain.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "farfield/gen/camera_path.h"
#include "farfield/terrain/flythrough.h"
#include "farfield/terrain/heightfield.h"

namespace farfield::eval {

// The viewpoints as a camera path of the given kind at 30 frames a second, up = +z.
gen::CameraPath terrainCameraPath(const std::vector<terrain::Viewpoint>& viewpoints, const std::string& kind);

// The Figure-8-style flythrough over hf (terrain/flythrough.h) as a camera path of kind "terrain-flythrough".
// Throws farfield::Error as flythroughPath does.
gen::CameraPath flythroughCameraPath(const terrain::Heightfield& hf, const terrain::FlythroughOptions& options,
                                     terrain::FlythroughLandmarks* landmarks = nullptr);

// The same path with n frames: eye, look-at, up and field of view interpolated linearly along it; the first and
// last frames are kept. path must have a frame; n = 1 gives its first frame.
gen::CameraPath resampleCameraPath(const gen::CameraPath& path, size_t n);

// Near and far planes (metres) for the path over hf: near 2 m, far 5% beyond the farthest corner of the terrain's
// bounds from any eye on the path (at least 1000 m).
struct ClipPlanes {
  float near_plane = 2.0f;
  float far_plane = 1000.0f;
};
ClipPlanes terrainClipPlanes(const terrain::Heightfield& hf, const gen::CameraPath& path);

}  // namespace farfield::eval
