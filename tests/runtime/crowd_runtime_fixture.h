// Shared by the crowd runtime tests (test_crowd_runtime.cpp, test_crowd_geometry_budget.cpp,
// test_crowd_impostor_atlas.cpp): the GL fixture, a square camera, a small atlas, the models' options, a frame check.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>

#include "farfield/core/math.h"
#include "farfield/gpu/context.h"
#include "farfield/image/image.h"
#include "farfield/impostor/multi_view.h"
#include "farfield/runtime/crowd_runtime.h"

namespace farfield::runtime::crowd_runtime_test {

// A square view from eye towards at (the camera's other settings at their defaults).
inline Camera viewCamera(Vec3 eye, Vec3 at, int size) {
  Camera camera;
  camera.eye = eye;
  camera.at = at;
  camera.width = camera.height = size;
  return camera;
}

class CrowdRuntimeGl : public ::testing::Test {
 protected:
  void SetUp() override { gpu::sharedHeadlessContext(); }
};

// A small atlas (8 x 3 views up to 45 degrees, 4 frames, 2 cm texels) over a palette of `poses`.
inline CrowdRuntimeOptions smallAtlas(int poses) {
  CrowdRuntimeOptions o;
  o.palette_poses = poses;
  o.frames = 4;
  o.grid = impostor::ViewGrid{8, 3, float(kPi / 4)};
  o.texel_m = 0.02f;
  return o;
}

// Whether two frames have the same colours, pixel for pixel.
inline bool same(const image::ColorImage& a, const image::ColorImage& b) {
  return std::equal(a.pixels().begin(), a.pixels().end(), b.pixels().begin(),
                    [](const image::Rgba8& x, const image::Rgba8& y) {
                      return x.r == y.r && x.g == y.g && x.b == y.b;
                    });
}

inline CrowdModelOptions manOptions() {
  CrowdModelOptions mo;
  mo.facing_deg = 0.0f;
  return mo;
}

inline CrowdModelOptions foxOptions() {
  CrowdModelOptions mo;
  mo.height_m = 0.8f;
  return mo;
}

}  // namespace farfield::runtime::crowd_runtime_test
