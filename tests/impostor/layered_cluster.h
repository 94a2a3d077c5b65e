// Shared by the layered impostor tests that render: a small cluster of boxes, its shaft, the bound and the cameras.
#pragma once

#include <vector>

#include "farfield/core/error_bound.h"
#include "farfield/core/math.h"
#include "farfield/core/shaft.h"
#include "impostor/impostor_fixture.h"

namespace farfield::impostor::test {

// A small cluster: boxes at different depths along the shaft's axis, overlapping in its view (occlusion edges).
struct Cluster {
  BoxScene s;
  std::vector<uint32_t> ids;
  Box3 box;
  Shaft shaft;
  Cluster() {
    ids.push_back(s.addBox({-6.0f, -10.0f, 0.0f}, {-1.0f, -6.0f, 6.0f}, {0.85f, 0.25f, 0.2f}));
    ids.push_back(s.addBox({-2.0f, -3.0f, 0.0f}, {3.0f, 1.0f, 9.0f}, {0.25f, 0.75f, 0.3f}));
    ids.push_back(s.addBox({1.0f, 4.0f, 0.0f}, {7.0f, 9.0f, 5.0f}, {0.2f, 0.35f, 0.85f}));
    ids.push_back(s.addBox({-7.0f, 5.0f, 2.0f}, {-2.0f, 10.0f, 8.0f}, {0.9f, 0.8f, 0.2f}));
    for (const Box3& b : s.boxes) box.expand(b);
    shaft = Shaft::make(box.center(), Vec3(0.0f, -1.0f, 0.3f), float(degToRad(30.0)), 60.0f);
  }
};

inline ErrorBound testBound() {
  ErrorBound bound;
  bound.pixels = 2.0;
  bound.width = bound.height = 128;
  bound.fov_y = degToRad(25.0);
  return bound;
}

inline Camera viewFrom(const Vec3& eye, const Shaft& shaft, const ErrorBound& bound) {
  Camera camera = makeCamera(eye, shaft.apex, bound.width, 0.5f, 2000.0f);
  camera.height = bound.height;
  camera.fov_y = float(bound.fov_y);
  return camera;
}

}  // namespace farfield::impostor::test
