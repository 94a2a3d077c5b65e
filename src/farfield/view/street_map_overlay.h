// The 2D map of the street graph (ImGui draw list): streets as lines, the viewer's current cell (an oriented street
// edge, FrameReport::cell) highlighted with an arrow along its direction, the current conservative problem view of a
// placement (its region's footprint) and the camera with its view direction and field of view.
#pragma once

#include <cstdint>
#include <optional>

#include "farfield/core/bounds.h"
#include "farfield/core/camera.h"
#include "farfield/store/placement_store.h"
#include "farfield/urban/street_graph.h"

struct ImDrawList;

namespace farfield::view {

// World (x, y) to map pixels: the box fitted into a canvas, north up, aspect kept.
struct MapTransform {
  Vec2 origin{0.0f};  // canvas pixel of the box's centre
  Vec2 centre{0.0f};  // world
  float scale = 1.0f; // pixels per metre
  Vec2 toMap(const Vec2& world) const { return origin + Vec2(world.x - centre.x, centre.y - world.y) * scale; }
};
// Fits `world` (with a 4 % margin) into the canvas at canvas_min with canvas_size pixels.
MapTransform fitMap(const Box2& world, const Vec2& canvas_min, const Vec2& canvas_size);

struct MapOverlay {
  const urban::StreetGraph* graph = nullptr;           // may be null: no streets
  uint32_t cell = urban::kNone;                        // half-edge to highlight
  const store::PlacementIndex* placement = nullptr;    // for the CPV
  uint32_t cpv = urban::kNone;
};

// Draws the map into the current ImGui window's remaining area (size pixels, square recommended).
void drawStreetMap(const MapOverlay& overlay, const Camera& camera, float size);

}  // namespace farfield::view
