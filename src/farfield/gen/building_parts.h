// The pieces of building geometry shared by the files of buildings.h: texture regions of the facade tile, the
// mesh writer and wall frames, and the facade (building_facades.cpp), roof (building_roofs.cpp) and landmark
// (building_landmarks.cpp) emitters. Internal to the gen module.
#pragma once

#include <cstdint>
#include <vector>

#include "farfield/gen/buildings.h"
#include "farfield/gen/textures.h"

namespace farfield::gen {

constexpr Vec3 kUp{0.0f, 0.0f, 1.0f};
constexpr float kRoofTile = 4.0f;  // metres per roof texture repeat

// Regions of the facade / landmark tile (textures.h) for trim geometry, so that ledges, sills, frames and
// balconies show plaster or frame paint rather than a tiny copy of the window. The plaster region lies above the
// window; the band left of the window holds no window at any v, so it may repeat vertically.
struct UvRect {
  Vec2 lo, hi;
};
constexpr UvRect kPlasterUv{{0.04f, 0.06f}, {0.22f, 0.18f}};
constexpr UvRect kFrameUv{{kWindowU0 - 0.025f, kWindowV0 + 0.1f}, {kWindowU0 - 0.005f, kWindowV1 - 0.1f}};
constexpr float kSideBandU0 = 0.03f, kSideBandU1 = kWindowU0 - 0.04f;

// Right of the edge: outside of a CCW polygon.
inline Vec2 outwardNormal(const Vec2& dir) { return Vec2(dir.y, -dir.x); }

// ---------------------------------------------------------------------------------------------------------------
// Mesh writing. Scratch meshes are reused between buildings, so pushes do not allocate once capacity is reached.

class MeshWriter {
 public:
  explicit MeshWriter(scene::Mesh& mesh) : m_(mesh) {}

  uint32_t vertex(const Vec3& p, const Vec3& n, const Vec2& uv) {
    m_.positions.push_back(p);
    m_.normals.push_back(n);
    m_.uvs.push_back(uv);
    return uint32_t(m_.positions.size() - 1);
  }
  void tri(uint32_t a, uint32_t b, uint32_t c) {
    m_.indices.push_back(a);
    m_.indices.push_back(b);
    m_.indices.push_back(c);
  }
  // A planar convex quad given in order around its boundary, either winding: it is wound so that its front face
  // looks along n (Newell's normal decides, so a quad with one collapsed edge works too).
  void quad(const Vec3& p0, const Vec3& p1, const Vec3& p2, const Vec3& p3, const Vec3& n, const Vec2& t0,
            const Vec2& t1, const Vec2& t2, const Vec2& t3) {
    const Vec3 newell = glm::cross(p1 - p0, p2 - p0) + glm::cross(p2 - p0, p3 - p0);
    const uint32_t i0 = vertex(p0, n, t0), i1 = vertex(p1, n, t1), i2 = vertex(p2, n, t2), i3 = vertex(p3, n, t3);
    if (glm::dot(newell, n) >= 0.0f) {
      tri(i0, i1, i2);
      tri(i0, i2, i3);
    } else {
      tri(i0, i2, i1);
      tri(i0, i3, i2);
    }
  }
  // Quad whose corners take the corners of a texture region: p0 -> (lo.x, hi.y), p1 -> (hi.x, hi.y),
  // p2 -> (hi.x, lo.y), p3 -> (lo.x, lo.y) (the region stretched over the quad).
  void quadUv(const Vec3& p0, const Vec3& p1, const Vec3& p2, const Vec3& p3, const Vec3& n, const UvRect& r) {
    quad(p0, p1, p2, p3, n, Vec2(r.lo.x, r.hi.y), r.hi, Vec2(r.hi.x, r.lo.y), r.lo);
  }
  void triangle(const Vec3& p0, const Vec3& p1, const Vec3& p2, const Vec3& n, const Vec2& t0, const Vec2& t1,
                const Vec2& t2) {
    const uint32_t i0 = vertex(p0, n, t0), i1 = vertex(p1, n, t1), i2 = vertex(p2, n, t2);
    if (glm::dot(glm::cross(p1 - p0, p2 - p0), n) >= 0.0f)
      tri(i0, i1, i2);
    else
      tri(i0, i2, i1);
  }
  scene::Mesh& mesh() { return m_; }

 private:
  scene::Mesh& m_;
};

// A wall's local frame: s along the edge from a, o outward from the wall plane, z up.
struct WallFrame {
  Vec2 a{0.0f};
  Vec2 dir{1.0f, 0.0f};
  Vec2 out{0.0f, -1.0f};
  float length = 0.0f;

  WallFrame(const Vec2& from, const Vec2& to) : a(from) {
    const Vec2 e = to - from;
    length = glm::length(e);
    if (length > 0.0f) {
      dir = e / length;
      out = outwardNormal(dir);
    }
  }
  Vec3 at(float s, float z, float o = 0.0f) const {
    const Vec2 p = a + dir * s + out * o;
    return Vec3(p.x, p.y, z);
  }
  Vec3 normal() const { return Vec3(out.x, out.y, 0.0f); }
  Vec3 along() const { return Vec3(dir.x, dir.y, 0.0f); }
};

// ---------------------------------------------------------------------------------------------------------------
// Facades

struct FacadeStyle {
  float grid_z = 0.0f;  // z where floor 0 starts (the facade texture's vertical origin)
  float floor_h = 3.2f;
  float bay = 3.2f;
  bool windows = false;    // recessed windows (detail >= 2)
  bool frames = false;     // window frames and sills (detail >= 3)
  bool mullions = false;   // detail 4
  bool balconies = false;  // on floors >= 1, every other bay
  float recess = 0.25f;    // depth of the window recess
};

// One wall (edge a -> b of a CCW footprint, outside to the right) from z0 to z1. Without windows a single quad;
// with windows a grid of wall cells around the window openings (vertices shared, no T-junctions), each opening
// a recess (glass at the back, four reveals) and, by style, frames, sills, mullions and balconies.
void emitWall(MeshWriter& w, const Vec2& a, const Vec2& b, float z0, float z1, const FacadeStyle& st);

// A horizontal band (ledge, cornice) around the exposed edges of a footprint, standing `dist` out of the walls,
// from z_lo to z_hi: front, top and bottom faces per exposed edge, closed at its ends against unexposed walls.
void emitBand(MeshWriter& w, const Polygon2& p, const std::vector<uint8_t>& exposed, float z_lo, float z_hi,
              float dist);

FacadeStyle styleFor(const Building& b, int detail, float grid_z);
std::vector<uint8_t> exposedMask(const Building& b);

// Ledges above the ground floor (detail 1-3) or at every floor (detail 4), and a cornice at the eaves.
void emitLedges(MeshWriter& w, const Polygon2& p, const std::vector<uint8_t>& exposed, float z0, float z1,
                float floor_h, int detail, const std::vector<uint8_t>* cornice_mask = nullptr);

// ---------------------------------------------------------------------------------------------------------------
// Roofs

// Flat horizontal polygon at height z, facing up, uvs in metres / kRoofTile relative to its first vertex.
void emitFlat(MeshWriter& w, const Polygon2& p, float z);

// Pyramid (spire) from a CCW base polygon at z up to an apex; uvs in the windowless band left of the tile's
// window, repeating every 4 m up the slope.
void emitPyramid(MeshWriter& w, const Polygon2& p, float z, const Vec3& apex);

// Horizontal ring between a CCW outer polygon and a CCW inner polygon with the same vertex count (setback roofs),
// textured with the windowless band of the tile.
void emitRing(MeshWriter& w, const Polygon2& outer, const Polygon2& inner, float z);

// ---------------------------------------------------------------------------------------------------------------
// Landmarks

void appendTower(const Building& b, int detail, BuildingMeshes& out);
void appendChurch(const Building& b, int detail, BuildingMeshes& out);

}  // namespace farfield::gen
