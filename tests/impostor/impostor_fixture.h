// Shared by the impostor tests that render: scenes of boxes, the shared headless context, rendering helpers.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "farfield/core/bounds.h"
#include "farfield/core/camera.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/render_target.h"
#include "farfield/gpu/renderer.h"
#include "farfield/impostor/drawable.h"
#include "farfield/scene/builtin.h"
#include "farfield/scene/scene.h"

namespace farfield::impostor::test {

class ImpostorGpuTest : public ::testing::Test {
 protected:
  void SetUp() override {
    gpu::sharedHeadlessContext();
    renderer_ = std::make_unique<gpu::Renderer>();
  }
  std::unique_ptr<gpu::Renderer> renderer_;
};

// A scene of axis-aligned boxes (one object each, flat colours), optionally on a ground quad; keeps the boxes for
// independent geometric checks.
struct BoxScene {
  scene::Scene scene;
  std::vector<Box3> boxes;
  bool has_ground = false;
  Vec2 ground_lo{0.0f}, ground_hi{0.0f};

  uint32_t addBox(const Vec3& lo, const Vec3& hi, const Vec3& color) {
    scene::Material m;
    m.base_color = Vec4(color, 1.0f);
    scene::Object o;
    o.parts.push_back({scene.addMesh(scene::makeBox(lo, hi)), scene.addMaterial(m)});
    boxes.push_back(Box3::fromPoints(lo, hi));
    return scene.addObject(o);
  }
  uint32_t addGround(const Vec2& lo, const Vec2& hi, std::shared_ptr<const image::ColorImage> texture = nullptr) {
    scene::Material m;
    m.base_color = Vec4(0.55f, 0.6f, 0.5f, 1.0f);
    if (texture) {
      m.base_color = Vec4(1.0f);
      m.texture = std::move(texture);
    }
    scene::Object o;
    o.parts.push_back({scene.addMesh(scene::makeGroundQuad(lo, hi, 8.0f)), scene.addMaterial(m)});
    has_ground = true;
    ground_lo = lo;
    ground_hi = hi;
    return scene.addObject(o);
  }
  // Distance from p to the nearest surface of the scene (box boundaries, ground quad).
  double distanceToSurface(const Vec3& p) const {
    double best = 1e30;
    for (const Box3& b : boxes) {
      const DVec3 lo(b.lo), hi(b.hi), q(p);
      const DVec3 outside = glm::max(glm::max(lo - q, q - hi), DVec3(0.0));
      double d = glm::length(outside);
      if (d == 0.0)  // inside: distance to the nearest face
        d = std::min({q.x - lo.x, hi.x - q.x, q.y - lo.y, hi.y - q.y, q.z - lo.z, hi.z - q.z});
      best = std::min(best, d);
    }
    if (has_ground) {
      const double dx = std::max({double(ground_lo.x) - p.x, double(p.x) - ground_hi.x, 0.0});
      const double dy = std::max({double(ground_lo.y) - p.y, double(p.y) - ground_hi.y, 0.0});
      best = std::min(best, std::sqrt(dx * dx + dy * dy + double(p.z) * p.z));
    }
    return best;
  }
};

inline Camera makeCamera(const Vec3& eye, const Vec3& at, int size, float near_plane = 0.5f,
                         float far_plane = 2000.0f) {
  Camera c;
  c.eye = eye;
  c.at = at;
  c.width = c.height = size;
  c.near_plane = near_plane;
  c.far_plane = far_plane;
  return c;
}

struct Frame {
  image::ColorImage color;
  image::IdImage ids;
  image::DepthImage depth;
};

inline Frame renderItems(gpu::Renderer& renderer, const Camera& camera, const std::vector<gpu::DrawItem>& items) {
  gpu::RenderTarget target(camera.width, camera.height);
  renderer.render(camera, items, target);
  return {target.readColor(), target.readIds(), target.readDepth()};
}

}  // namespace farfield::impostor::test
