// Building meshes from real footprints: walls extruded from every ring (holes included) between a base and a top
// height, a flat roof triangulated with its holes, or a simple pitched roof. Texture coordinates follow the
// procedural city (gen/buildings.h), so the same facade and roof textures fit: facade u = metres along the wall /
// bay width, v = metres below the top of the walls / floor height; roof uv = metres / 4.
#pragma once

#include <vector>

#include "farfield/core/polygon2d.h"
#include "farfield/scene/mesh.h"

namespace farfield::geodata {

enum class RoofKind { Flat, Gabled, Pyramidal };

// A footprint polygon: outer ring counter-clockwise, holes clockwise (extrudeBuilding fixes the orientation of
// rings given the other way), no repeated closing vertex.
struct FootprintPolygon {
  Polygon2 outer;
  std::vector<Polygon2> holes;
};

struct ExtrusionShape {
  float base = 0.0f;  // bottom of the walls (z, metres)
  float top = 10.0f;  // top of the building: the roof ridge or apex for pitched roofs, the flat roof otherwise
  RoofKind roof = RoofKind::Flat;
  float roof_height = 0.0f;  // pitched roofs: from the eaves to the ridge/apex (the walls end at top - roof_height)
  float floor_height = 3.2f;
  float bay_width = 3.2f;
};

// The roof a footprint can carry: Gabled needs a 4-vertex outer ring without holes, Pyramidal a convex outer
// ring without holes; anything else (or roof_height not below top - base) falls back to Flat.
RoofKind feasibleRoof(const FootprintPolygon& polygon, const ExtrusionShape& shape);

// Appends walls (and gable ends) to `facades`, roofs (and the underside of a raised building, base > 0) to
// `roofs`: positions, flat normals, uvs, counter-clockwise triangles seen from outside. Returns false (appending
// nothing) when the outer ring has fewer than 3 vertices or the roof cannot be triangulated.
bool extrudeBuilding(const FootprintPolygon& polygon, const ExtrusionShape& shape, scene::Mesh& facades,
                     scene::Mesh& roofs);

}  // namespace farfield::geodata
