// Shared by the GPU tests: every test runs on the one process-wide headless context.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "farfield/core/camera.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/renderer.h"
#include "farfield/image/image.h"

namespace farfield::gpu::test {

class GpuTest : public ::testing::Test {
 protected:
  // Also makes the shared context current again after a test that used another one (the window test).
  void SetUp() override { sharedHeadlessContext(); }
};

// 8-bit value the GPU stores for a colour channel in [0, 1].
inline int toByte(float v) { return int(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); }

inline ::testing::AssertionResult colorNear(const image::Rgba8& got, const Vec3& want, int tolerance = 2) {
  for (int c = 0; c < 3; ++c)
    if (std::abs(int(got[c]) - toByte(want[c])) > tolerance)
      return ::testing::AssertionFailure() << "got (" << int(got.r) << ", " << int(got.g) << ", " << int(got.b)
                                           << "), want (" << toByte(want.r) << ", " << toByte(want.g) << ", "
                                           << toByte(want.b) << ")";
  return ::testing::AssertionSuccess();
}

// Camera at `eye` looking at `at` with a small near/far range (good depth precision for the checks).
inline Camera testCamera(const Vec3& eye, const Vec3& at, int size = 128) {
  Camera camera;
  camera.eye = eye;
  camera.at = at;
  camera.width = camera.height = size;
  camera.near_plane = 0.1f;
  camera.far_plane = 100.0f;
  return camera;
}

// The shading model written out independently of the shader: albedo * (ambient + light colour * max(n . -l, 0)).
inline Vec3 expectedLit(const Vec3& albedo, const Vec3& normal, const LightSettings& light) {
  const float ndl = std::max(glm::dot(glm::normalize(normal), -glm::normalize(light.direction)), 0.0f);
  return albedo * (Vec3(light.ambient) + light.color * ndl);
}

// Pixel (column, row) containing the projection of a world point.
inline IVec2 pixelOf(const Camera& camera, const Vec3& world) {
  const Vec3 p = camera.project(world);
  return IVec2(int(std::floor(p.x)), int(std::floor(p.y)));
}

inline Vec3 skyColor(const LightSettings& light) { return Vec3(light.sky_color); }

}  // namespace farfield::gpu::test
