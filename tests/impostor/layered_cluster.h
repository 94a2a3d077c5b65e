// Shared by the layered impostor tests that render: a small cluster of boxes, its shaft, the bound and the cameras.
#pragma once

#include <vector>

#include "farfield/core/error_bound.h"
#include "farfield/core/math.h"
#include "farfield/core/shaft.h"
#include "farfield/image/metrics.h"
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

// Two drawings of one impostor seen from viewpoints of the cluster's shaft show the same pixels: ids but for a
// thousandth of the frame, colours but for a thousandth beyond 8/255 (rounding of moved or split quads' texture
// coordinates), and the impostor covers at least a twentieth of the frame.
inline void expectSameImage(gpu::Renderer& renderer, const Cluster& c, const ErrorBound& bound,
                            const std::vector<gpu::DrawItem>& a_items, const std::vector<gpu::DrawItem>& b_items) {
  for (const float t : {0.0f, 0.3f, 0.7f, 1.0f}) {
    const Camera camera = viewFrom(c.shaft.sample(t, 1.0f, 0.5f, 2.0f * c.shaft.min_distance), c.shaft, bound);
    const Frame a = renderItems(renderer, camera, a_items);
    const Frame b = renderItems(renderer, camera, b_items);
    size_t ids_differ = 0, drawn = 0;
    for (size_t p = 0; p < a.ids.pixelCount(); ++p) {
      ids_differ += a.ids.pixels()[p] != b.ids.pixels()[p] ? 1 : 0;
      drawn += b.ids.pixels()[p] != 0 ? 1 : 0;
    }
    EXPECT_GT(drawn, a.ids.pixelCount() / 20) << "viewpoint " << t;
    EXPECT_LE(ids_differ, a.ids.pixelCount() / 1000) << "viewpoint " << t;
    EXPECT_LT(image::shareOverThreshold(a.color, b.color, 8), 0.001) << "viewpoint " << t;
  }
}

}  // namespace farfield::impostor::test
