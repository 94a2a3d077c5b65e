#include "farfield/view/street_map_overlay.h"

#include <imgui.h>

#include <algorithm>
#include <cmath>

namespace farfield::view {
namespace {
ImVec2 im(const Vec2& v) { return ImVec2(v.x, v.y); }
}  // namespace

MapTransform fitMap(const Box2& world, const Vec2& canvas_min, const Vec2& canvas_size) {
  MapTransform t;
  const Vec2 extent = glm::max(world.extent() * 1.08f, Vec2(1.0f));
  t.scale = std::min(canvas_size.x / extent.x, canvas_size.y / extent.y);
  t.centre = (world.lo + world.hi) * 0.5f;
  t.origin = canvas_min + canvas_size * 0.5f;
  return t;
}

void drawStreetMap(const MapOverlay& overlay, const Camera& camera, float size) {
  const ImVec2 p0 = ImGui::GetCursorScreenPos();
  const Vec2 canvas_min(p0.x, p0.y), canvas_size(size, size);
  ImGui::InvisibleButton("map", ImVec2(size, size));
  ImDrawList* draw = ImGui::GetWindowDrawList();
  draw->AddRectFilled(p0, ImVec2(p0.x + size, p0.y + size), IM_COL32(24, 26, 30, 255));

  Box2 world;
  if (overlay.graph && overlay.graph->streetCount() > 0) world = overlay.graph->bounds();
  world.expand(Vec2(camera.eye));
  if (overlay.placement) {
    world.expand(Vec2(overlay.placement->view_space.lo));
    world.expand(Vec2(overlay.placement->view_space.hi));
  }
  const MapTransform t = fitMap(world, canvas_min, canvas_size);
  draw->PushClipRect(p0, ImVec2(p0.x + size, p0.y + size), true);

  if (overlay.placement) {
    const Box3& v = overlay.placement->view_space;
    draw->AddRect(im(t.toMap(Vec2(v.lo.x, v.hi.y))), im(t.toMap(Vec2(v.hi.x, v.lo.y))), IM_COL32(90, 90, 140, 255));
    if (overlay.cpv < overlay.placement->cpvs.size()) {
      const Box3& r = overlay.placement->cpvs[overlay.cpv].region;
      draw->AddRectFilled(im(t.toMap(Vec2(r.lo.x, r.hi.y))), im(t.toMap(Vec2(r.hi.x, r.lo.y))),
                          IM_COL32(240, 90, 255, 110));
      draw->AddRect(im(t.toMap(Vec2(r.lo.x, r.hi.y))), im(t.toMap(Vec2(r.hi.x, r.lo.y))), IM_COL32(240, 90, 255, 255));
    }
  }
  if (overlay.graph) {
    const urban::StreetGraph& g = *overlay.graph;
    for (uint32_t e = 0; e < g.halfEdgeCount(); e += 2) {
      const float width = std::max(1.0f, g.width(e) * t.scale * 0.35f);
      draw->AddLine(im(t.toMap(g.originPosition(e))), im(t.toMap(g.destinationPosition(e))),
                    IM_COL32(150, 150, 150, 255), std::min(width, 6.0f));
    }
    if (overlay.cell < g.halfEdgeCount()) {
      const Vec2 a = t.toMap(g.originPosition(overlay.cell)), b = t.toMap(g.destinationPosition(overlay.cell));
      draw->AddLine(im(a), im(b), IM_COL32(255, 170, 40, 255), 4.0f);
      // Arrow head at the destination: the cell is the street edge in this direction.
      const Vec2 d = glm::length(b - a) > 0.0f ? glm::normalize(b - a) : Vec2(1.0f, 0.0f);
      const Vec2 n(-d.y, d.x);
      draw->AddTriangleFilled(im(b), im(b - d * 10.0f + n * 5.0f), im(b - d * 10.0f - n * 5.0f),
                              IM_COL32(255, 170, 40, 255));
    }
  }
  // The camera: its position and the two edges of its horizontal field of view.
  const Vec2 eye = t.toMap(Vec2(camera.eye));
  const Vec3 f = camera.forward();
  const float heading = std::atan2(f.y, f.x), half = camera.fovX() * 0.5f;
  const float reach = size * 0.08f;
  for (float side : {-1.0f, 1.0f}) {
    const float a = heading + side * half;
    const Vec2 tip = eye + Vec2(std::cos(a), -std::sin(a)) * reach;
    draw->AddLine(im(eye), im(tip), IM_COL32(80, 220, 255, 255), 1.5f);
  }
  draw->AddCircleFilled(im(eye), 4.0f, IM_COL32(80, 220, 255, 255));
  draw->PopClipRect();
}

}  // namespace farfield::view
