// A constructed street for the multi-mesh and validity tests (tests/bake): a 3 x 2 grid of blocks, streets along
// y = -100, 0, 100 and x = 0, 50, 150, 450:
//
//      y=100  +----+---------+----------------------------+
//             |    |  [NL]   |                   [FL]     |
//      y=0    P====Q---------+----------------------------+      the cell: the street (0,0) -> (50,0)
//             |[L] |    [NR] |                       [FR] |
//      y=-100 +----+---------+----------------------------+
//            x=0  50        150                          450
//
// Objects: 1 the ground (shared: its footprint covers every block); L, a low building in a block touching the
// street (local model: geometry, in no impostor); the far model: NL, a 40 m building 10-30 m ahead of Q on the left;
// FL, a large block 250-290 m ahead of Q behind it; NR, a building on the right; FR, a tower far behind NR. From P,
// NL hides most of FL and NR part of FR; walking to Q, NL and NR slide out to the sides and uncover them (tens of
// pixels): the de-occlusion a single mesh fills with "rubber sheets".
#pragma once

#include <vector>

#include "farfield/scene/builtin.h"
#include "farfield/scene/scene.h"
#include "farfield/urban/cells.h"
#include "farfield/urban/street_graph.h"

namespace farfield::test {

struct Street {
  scene::Scene scene;
  urban::StreetGraph graph;
  uint32_t cell = 0;
  uint32_t ground = 0, local = 0, near_left = 0, far_left = 0, near_right = 0, far_right = 0;
};

inline Street constructedStreet() {
  Street s;
  const std::vector<float> xs{0, 50, 150, 450}, ys{-100, 0, 100};
  std::vector<Vec2> junctions;
  for (float y : ys)
    for (float x : xs) junctions.emplace_back(x, y);
  std::vector<urban::Street> streets;
  const auto at = [&](size_t ix, size_t iy) { return uint32_t(iy * xs.size() + ix); };
  for (size_t iy = 0; iy < ys.size(); ++iy)
    for (size_t ix = 0; ix + 1 < xs.size(); ++ix) streets.push_back({at(ix, iy), at(ix + 1, iy), 12.0f});
  for (size_t ix = 0; ix < xs.size(); ++ix)
    for (size_t iy = 0; iy + 1 < ys.size(); ++iy) streets.push_back({at(ix, iy), at(ix, iy + 1), 12.0f});
  s.graph = urban::StreetGraph::build(junctions, streets, "constructed street");
  s.cell = urban::kNone;
  for (uint32_t e = 0; e < s.graph.halfEdgeCount(); ++e)
    if (s.graph.originPosition(e) == Vec2(0, 0) && s.graph.destinationPosition(e) == Vec2(50, 0)) s.cell = e;

  const auto add = [&](scene::Mesh mesh, const Vec3& color, std::vector<Vec2> footprint) {
    scene::Material m;
    m.base_color = Vec4(color, 1.0f);
    scene::Object o;
    o.parts.push_back({s.scene.addMesh(std::move(mesh)), s.scene.addMaterial(m)});
    o.footprint = std::move(footprint);
    return s.scene.addObject(o);
  };
  const auto box = [&](const Vec2& lo, const Vec2& hi, float height, const Vec3& color) {
    return add(scene::makeBox(Vec3(lo, 0.0f), Vec3(hi, height)), color,
               {{lo.x, lo.y}, {hi.x, lo.y}, {hi.x, hi.y}, {lo.x, hi.y}});
  };
  s.ground = add(scene::makeGroundQuad(Vec2(-200, -300), Vec2(700, 300)), Vec3(0.5f, 0.55f, 0.45f),
                 {{-200, -300}, {700, -300}, {700, 300}, {-200, 300}});
  s.local = box({10, -40}, {40, -8}, 15.0f, {0.7f, 0.7f, 0.6f});
  s.near_left = box({60, 6}, {80, 30}, 40.0f, {0.9f, 0.5f, 0.3f});
  s.far_left = box({300, 20}, {340, 80}, 50.0f, {0.3f, 0.4f, 0.9f});
  s.near_right = box({100, -60}, {130, -20}, 25.0f, {0.8f, 0.8f, 0.3f});
  s.far_right = box({350, -70}, {380, -30}, 70.0f, {0.5f, 0.8f, 0.5f});
  s.scene.updateBounds();
  return s;
}

}  // namespace farfield::test
