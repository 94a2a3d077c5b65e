// Camera paths for the terrain experiments of Chen et al. 1999 (section 4, Figure 8).
#include "farfield/eval/terrain_paths.h"

#include <algorithm>

#include "farfield/core/check.h"

namespace farfield::eval {

gen::CameraPath terrainCameraPath(const std::vector<terrain::Viewpoint>& viewpoints, const std::string& kind) {
  gen::CameraPath path;
  path.kind = kind;
  path.fps = 30.0f;
  for (const terrain::Viewpoint& v : viewpoints) {
    gen::PathFrame f;
    f.eye = v.eye;
    f.at = v.at;
    f.up = Vec3(0.0f, 0.0f, 1.0f);
    f.fov_y = v.fov_y;
    path.frames.push_back(f);
  }
  return path;
}

gen::CameraPath flythroughCameraPath(const terrain::Heightfield& hf, const terrain::FlythroughOptions& options,
                                     terrain::FlythroughLandmarks* landmarks) {
  return terrainCameraPath(terrain::flythroughPath(hf, options, landmarks), "terrain-flythrough");
}

gen::CameraPath resampleCameraPath(const gen::CameraPath& path, size_t n) {
  FF_CHECK(!path.frames.empty());
  gen::CameraPath out = path;
  out.frames.clear();
  const size_t m = path.frames.size();
  for (size_t i = 0; i < n; ++i) {
    const double t = n > 1 ? double(i) * double(m - 1) / double(n - 1) : 0.0;
    const size_t a = std::min(size_t(t), m - 1), b = std::min(a + 1, m - 1);
    const float s = float(t - double(a));
    gen::PathFrame f;
    f.eye = glm::mix(path.frames[a].eye, path.frames[b].eye, s);
    f.at = glm::mix(path.frames[a].at, path.frames[b].at, s);
    f.up = glm::mix(path.frames[a].up, path.frames[b].up, s);
    f.fov_y = glm::mix(path.frames[a].fov_y, path.frames[b].fov_y, s);
    out.frames.push_back(f);
  }
  return out;
}

ClipPlanes terrainClipPlanes(const terrain::Heightfield& hf, const gen::CameraPath& path) {
  const Box3 b = hf.bounds();
  float farthest = 0.0f;
  for (const gen::PathFrame& f : path.frames)
    for (int k = 0; k < 8; ++k) {
      const Vec3 c((k & 1) ? b.hi.x : b.lo.x, (k & 2) ? b.hi.y : b.lo.y, (k & 4) ? b.hi.z : b.lo.z);
      farthest = std::max(farthest, glm::length(c - f.eye));
    }
  return {2.0f, std::max(1000.0f, farthest * 1.05f)};
}

}  // namespace farfield::eval
