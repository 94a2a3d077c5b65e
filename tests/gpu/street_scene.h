// A street canyon for the occlusion tests: two rows of tall walls along y, many small towers behind them, a few in the
// street and kiosks along the walls (seen over the wall's depth alone, nearly as far as it: a test that hid boxes a
// little too eagerly would drop them). With `varied`, also what the arena must draw like the renderer: a textured
// ground, objects under rotated, uniformly and non-uniformly scaled and mirrored transforms, a double-sided material
// and spheres (clusters with narrow normal cones).
#pragma once

#include <cmath>
#include <random>

#include "farfield/core/camera.h"
#include "farfield/scene/builtin.h"
#include "farfield/scene/scene.h"

namespace farfield::gpu::test {

inline scene::Scene streetCanyonScene(bool varied = false) {
  scene::Scene scene;
  std::mt19937 rng(21);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  scene::Material wall;
  wall.base_color = Vec4(0.8f, 0.7f, 0.6f, 1.0f);
  const uint32_t walls = scene.addMaterial(wall);
  wall.base_color = Vec4(0.3f, 0.4f, 0.8f, 1.0f);
  const uint32_t towers = scene.addMaterial(wall);
  for (int side = -1; side <= 1; side += 2)
    for (int k = 0; k < 6; ++k) {
      scene::Object object;
      const float x0 = float(side) * 6.0f + (side > 0 ? 0.0f : -1.0f);
      object.parts.push_back({scene.addMesh(scene::makeBox(Vec3(x0, k * 20.0f - 60.0f, 0.0f),
                                                           Vec3(x0 + 1.0f, k * 20.0f - 40.5f, 15.0f))),
                              walls});
      scene.addObject(std::move(object));
    }
  for (int i = 0; i < 120; ++i) {
    scene::Object object;
    const float side = i % 5 == 0 ? 0.0f : (i % 2 ? 1.0f : -1.0f);
    const Vec3 lo(side == 0.0f ? -3.0f + 5.0f * u(rng) : side * (9.0f + 40.0f * u(rng)), -60.0f + 120.0f * u(rng),
                  0.0f);
    const Vec3 size(0.5f + 2.0f * u(rng), 0.5f + 2.0f * u(rng), side == 0.0f ? 1.0f : 3.0f + 25.0f * u(rng));
    object.parts.push_back({scene.addMesh(scene::makeBox(lo, lo + size)), towers});
    scene.addObject(std::move(object));
  }
  for (int i = 0; i < 30; ++i) {
    scene::Object object;
    const float side = i % 2 ? 1.0f : -1.0f;
    const Vec3 lo(side > 0 ? 4.6f + 0.3f * u(rng) : -5.9f + 0.3f * u(rng), -60.0f + 120.0f * u(rng), 0.5f);
    object.parts.push_back({scene.addMesh(scene::makeBox(lo, lo + Vec3(1.0f, 1.0f, 1.0f + 2.0f * u(rng)))), walls});
    scene.addObject(std::move(object));
  }
  if (varied) {
    const scene::Scene cubes = scene::builtinScene("cubes");  // its ground has a checker texture
    scene::Material ground;
    for (const scene::Material& m : cubes.materials)
      if (m.texture) ground = m;
    const uint32_t ground_material = scene.addMaterial(ground);
    scene::Object floor;
    floor.parts.push_back({scene.addMesh(scene::makeGroundQuad(Vec2(-60.0f, -70.0f), Vec2(60.0f, 70.0f), 4.0f)),
                           ground_material});
    scene.addObject(std::move(floor));
    scene::Material sheet;
    sheet.base_color = Vec4(0.9f, 0.3f, 0.2f, 1.0f);
    sheet.double_sided = true;
    const uint32_t sheets = scene.addMaterial(sheet);
    const uint32_t ball = scene.addMesh(scene::makeSphere(1.0f, 24, 12));
    const uint32_t cube = scene.addMesh(scene::makeUnitCube());
    for (int i = 0; i < 40; ++i) {
      scene::Object object;
      const float angle = 6.2831853f * u(rng);
      const Vec3 at(-4.0f + 8.0f * u(rng), -55.0f + 110.0f * u(rng), 0.6f + 2.0f * u(rng));
      Mat4 m = glm::translate(Mat4(1.0f), at) * glm::rotate(Mat4(1.0f), angle, Vec3(0.3f, 0.2f, 1.0f));
      switch (i % 4) {
        case 0: m = m * glm::scale(Mat4(1.0f), Vec3(0.4f + u(rng))); break;                    // uniform
        case 1: m = m * glm::scale(Mat4(1.0f), Vec3(0.3f, 0.8f, 1.2f)); break;                  // non-uniform
        case 2: m = m * glm::scale(Mat4(1.0f), Vec3(-0.7f, 0.7f, 0.7f)); break;                 // mirrored
        default: m = m * glm::scale(Mat4(1.0f), Vec3(0.6f)); break;
      }
      object.transform = m;
      object.parts.push_back({i % 3 == 0 ? cube : ball, i % 4 == 3 ? sheets : (i % 2 ? towers : walls)});
      scene.addObject(std::move(object));
    }
  }
  return scene;
}

// A 96 x 64 camera in the street at eye height, or above the walls looking down a little.
inline Camera streetCanyonCamera(std::mt19937& rng, bool above) {
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  Camera camera;
  camera.width = 96;
  camera.height = 64;
  camera.near_plane = 0.2f;
  camera.far_plane = 500.0f;
  camera.eye = Vec3(3.0f * u(rng), 50.0f * u(rng), above ? 30.0f : 1.7f);
  camera.at = camera.eye + Vec3(0.8f * u(rng), u(rng), 0.2f * u(rng) - (above ? 0.5f : 0.0f));
  return camera;
}

}  // namespace farfield::gpu::test
