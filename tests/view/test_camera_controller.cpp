// The fly and walk cameras: walking keeps the eye 1.7 m above the ground under it, checked against an independent
// brute-force vertical ray / triangle test over every triangle of a small scene (a bumpy ground and a floating roof
// that must not lift the walker); flying moves along the view; looking turns and stays short of the poles.
#include "farfield/view/camera_controller.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <optional>
#include <random>

#include "farfield/extract/ground_height.h"
#include "farfield/scene/builtin.h"
#include "farfield/scene/scene.h"

namespace farfield::view {
namespace {

float bumpyHeight(float x, float y) { return 0.15f * x + 0.8f * std::sin(0.3f * y); }

// A 40 x 40 m ground of 2 m cells at bumpyHeight, and a roof (box) from 6 to 9 m over x, y in [2, 8].
scene::Scene groundScene() {
  scene::Scene s;
  scene::Mesh ground;
  const int n = 20;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const float x = -20.0f + 2.0f * float(i), y = -20.0f + 2.0f * float(j);
      ground.positions.push_back(Vec3(x, y, bumpyHeight(x, y)));
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const uint32_t a = uint32_t(j * (n + 1) + i), b = a + 1, c = a + uint32_t(n + 1), d = c + 1;
      ground.indices.insert(ground.indices.end(), {a, b, d, a, d, c});
    }
  ground.computeBounds();
  s.addMaterial({});
  scene::Object g;
  g.parts.push_back({s.addMesh(std::move(ground)), 0});
  s.addObject(g);
  scene::Object roof;
  roof.parts.push_back({s.addMesh(scene::makeBox(Vec3(2, 2, 6), Vec3(8, 8, 9))), 0});
  s.addObject(roof);
  s.updateBounds();
  return s;
}

// The lowest walkable (|normal z| > 0.2) triangle surface on the vertical line through (x, y), by testing every
// triangle: ray from high above straight down, Moller-Trumbore.
std::optional<float> bruteForceGround(const scene::Scene& s, float x, float y) {
  const DVec3 origin(x, y, 1000.0), dir(0.0, 0.0, -1.0);
  std::optional<float> lowest;
  for (const scene::Object& o : s.objects)
    for (const scene::Part& p : o.parts) {
      const scene::Mesh& m = s.meshes[p.mesh];
      for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
        const DVec3 a(Vec3(o.transform * Vec4(m.positions[m.indices[t]], 1.0f)));
        const DVec3 b(Vec3(o.transform * Vec4(m.positions[m.indices[t + 1]], 1.0f)));
        const DVec3 c(Vec3(o.transform * Vec4(m.positions[m.indices[t + 2]], 1.0f)));
        const DVec3 n = glm::cross(b - a, c - a);
        if (!(glm::length(n) > 0.0) || std::abs(n.z) / glm::length(n) <= 0.2) continue;
        const DVec3 e1 = b - a, e2 = c - a, pv = glm::cross(dir, e2);
        const double det = glm::dot(e1, pv);
        if (std::abs(det) < 1e-12) continue;
        const DVec3 tv = origin - a;
        const double u = glm::dot(tv, pv) / det;
        const DVec3 qv = glm::cross(tv, e1);
        const double v = glm::dot(dir, qv) / det;
        if (u < -1e-9 || v < -1e-9 || u + v > 1.0 + 1e-9) continue;
        const double dist = glm::dot(e2, qv) / det;
        const float z = float(origin.z - dist);
        if (!lowest || z < *lowest) lowest = z;
      }
    }
  return lowest;
}

TEST(CameraController, WalkKeepsTheEyeAboveTheGroundUnderIt) {
  const scene::Scene s = groundScene();
  const std::vector<uint32_t> ids{1, 2};
  const extract::GroundHeight ground(s, ids);
  const GroundFunction height = [&](float x, float y, float fallback) { return ground.at(x, y, fallback); };
  CameraController controller;
  controller.setPose(Vec3(-15.0f, -15.0f, 30.0f), Vec3(-14.0f, -14.0f, 30.0f));
  controller.snapToGround(height);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  size_t under_roof = 0;
  for (int step = 0; step < 400; ++step) {
    ControlInput input;
    input.forward = 0.5f + 0.5f * unit(rng);
    input.right = 0.3f * unit(rng);
    input.look_x = 20.0f * unit(rng);
    input.look_y = 5.0f * unit(rng);
    input.dt = 0.05;
    const Vec3 before = controller.eye();
    controller.update(input, Navigation::Walk, height);
    const Vec3 eye = controller.eye();
    if (std::abs(eye.x) > 19.0f || std::abs(eye.y) > 19.0f) {  // stay on the ground: turn back to the centre
      controller.setPose(eye, Vec3(0.0f, 0.0f, eye.z));
      continue;
    }
    // Moves in the ground plane at most speed * dt.
    EXPECT_LE(glm::length(Vec2(eye) - Vec2(before)), controller.settings().speed * 0.05f * 1.5f + 1e-4f);
    const std::optional<float> want = bruteForceGround(s, eye.x, eye.y);
    ASSERT_TRUE(want.has_value()) << eye.x << ", " << eye.y;
    EXPECT_NEAR(eye.z, *want + kWalkEyeHeight, 1e-3f) << "step " << step << " at " << eye.x << ", " << eye.y;
    EXPECT_NEAR(*want, bumpyHeight(eye.x, eye.y), 0.5f);  // the roof above never lifts the walker
    if (eye.x > 2 && eye.x < 8 && eye.y > 2 && eye.y < 8) ++under_roof;
  }
  // Walk under the roof on purpose too.
  controller.setPose(Vec3(5.0f, 0.0f, 1.0f), Vec3(5.0f, 1.0f, 1.0f));
  for (int step = 0; step < 20; ++step) {
    ControlInput input;
    input.forward = 1.0f;
    input.dt = 0.05;
    controller.update(input, Navigation::Walk, height);
    const std::optional<float> want = bruteForceGround(s, controller.eye().x, controller.eye().y);
    ASSERT_TRUE(want.has_value());
    EXPECT_NEAR(controller.eye().z, *want + kWalkEyeHeight, 1e-3f);
    if (controller.eye().y > 2 && controller.eye().y < 8) ++under_roof;
  }
  EXPECT_GT(under_roof, 0u);
}

TEST(CameraController, FlyMovesAlongTheViewAndUpDown) {
  CameraController c;
  c.setPose(Vec3(0.0f, 0.0f, 10.0f), Vec3(1.0f, 1.0f, 11.0f));
  const Vec3 forward = c.forward();
  EXPECT_NEAR(glm::length(forward - glm::normalize(Vec3(1, 1, 1))), 0.0f, 1e-5f);
  ControlInput input;
  input.forward = 1.0f;
  input.dt = 0.5;
  c.update(input, Navigation::Fly);
  EXPECT_NEAR(glm::length(c.eye() - (Vec3(0, 0, 10) + 5.0f * forward)), 0.0f, 1e-4f);
  input = {};
  input.up = 1.0f;
  input.fast = true;
  input.dt = 0.1;
  const Vec3 before = c.eye();
  c.update(input, Navigation::Fly);
  EXPECT_NEAR(glm::length(c.eye() - (before + Vec3(0, 0, 5.0f))), 0.0f, 1e-4f);  // 10 m/s x 5 x 0.1 s
  // The camera looks where the controller points, with +z up and the slider's field of view.
  c.settings().fov_deg = 75.0f;
  const Camera camera = c.camera(64, 32);
  EXPECT_NEAR(glm::length(camera.forward() - forward), 0.0f, 1e-5f);
  EXPECT_NEAR(camera.fov_y, float(degToRad(75.0)), 1e-6f);
  EXPECT_NO_THROW(camera.validate());
}

TEST(CameraController, LookingTurnsAndStopsShortOfThePoles) {
  CameraController c;
  c.setPose(Vec3(0.0f), Vec3(1.0f, 0.0f, 0.0f));
  ControlInput input;
  input.look_x = 100.0f;  // drag right: turn right (clockwise seen from above)
  c.update(input, Navigation::Fly);
  EXPECT_NEAR(c.yaw(), -100.0f * c.settings().radians_per_pixel, 1e-5f);
  input = {};
  input.look_y = -1e6f;  // drag far up
  c.update(input, Navigation::Fly);
  EXPECT_LT(c.pitch(), float(kPi / 2));
  EXPECT_GT(c.pitch(), float(degToRad(85.0)));
  EXPECT_NO_THROW(c.camera(32, 32).validate());  // +z up stays usable
}

}  // namespace
}  // namespace farfield::view
