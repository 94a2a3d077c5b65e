// Buildings of a city block from its footprint inward, to stand in for the test cities of the impostor papers
// (Sillion 1997 section 5 and Decoret 1999 section 6: Montmartre, 146 blocks of houses around a church landmark),
// with facade detail as real geometry so that polygon counts scale with the detail level.
#include "farfield/gen/buildings.h"

#include <algorithm>
#include <cmath>
#include <tuple>

#include "farfield/core/check.h"
#include "farfield/gen/textures.h"

namespace farfield::gen {

float Rng::normal() {
  // Box-Muller; u1 in (0, 1] so the logarithm stays finite.
  const float u1 = 1.0f - uniform();
  const float u2 = uniform();
  return std::sqrt(-2.0f * std::log(u1)) * std::cos(float(2.0 * kPi) * u2);
}

uint64_t mixSeed(uint64_t a, uint64_t b) {
  Rng rng(a ^ (b * 0xd1b54a32d192ed03ull + 0x8cb92ba72f3d8dd7ull));
  rng.next();
  return rng.next();
}

void BuildingMeshes::clear() {
  for (scene::Mesh* m : {&facades, &roofs, &landmark}) {
    m->positions.clear();
    m->normals.clear();
    m->uvs.clear();
    m->indices.clear();
  }
}

namespace {

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

Vec2 outwardNormal(const Vec2& dir) { return Vec2(dir.y, -dir.x); }  // right of the edge: outside of a CCW polygon

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

// Box standing out of a wall: s in [s0, s1], o in [o0, o1] (the face at o0, against the wall, is not drawn), z in
// [z0, z1]. Faces: front, top, bottom (unless !draw_bottom), two ends, each stretched over the texture region uvr.
void wallBox(MeshWriter& w, const WallFrame& f, float s0, float s1, float o0, float o1, float z0, float z1,
             const UvRect& uvr, bool draw_bottom = true) {
  const Vec3 n = f.normal(), d = f.along();
  w.quadUv(f.at(s0, z0, o1), f.at(s1, z0, o1), f.at(s1, z1, o1), f.at(s0, z1, o1), n, uvr);    // front
  w.quadUv(f.at(s0, z1, o1), f.at(s1, z1, o1), f.at(s1, z1, o0), f.at(s0, z1, o0), kUp, uvr);  // top
  if (draw_bottom)
    w.quadUv(f.at(s0, z0, o0), f.at(s1, z0, o0), f.at(s1, z0, o1), f.at(s0, z0, o1), -kUp, uvr);  // bottom
  w.quadUv(f.at(s0, z0, o0), f.at(s0, z0, o1), f.at(s0, z1, o1), f.at(s0, z1, o0), -d, uvr);      // end at s0
  w.quadUv(f.at(s1, z0, o1), f.at(s1, z0, o0), f.at(s1, z1, o0), f.at(s1, z1, o1), d, uvr);       // end at s1
}

// Double-sided thin panel (balcony railings): the same quad wound both ways.
void panel(MeshWriter& w, const Vec3& p0, const Vec3& p1, const Vec3& p2, const Vec3& p3, const Vec3& n,
           const UvRect& uvr) {
  w.quadUv(p0, p1, p2, p3, n, uvr);
  w.quadUv(p0, p1, p2, p3, -n, uvr);
}

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
void emitWall(MeshWriter& w, const Vec2& a, const Vec2& b, float z0, float z1, const FacadeStyle& st) {
  const WallFrame f(a, b);
  if (f.length < 1e-3f || z1 <= z0) return;
  const int bays = std::max(1, int(std::lround(f.length / st.bay)));
  const float bw = f.length / float(bays);
  auto uv = [&](float s, float z) { return Vec2(s / bw, -(z - st.grid_z) / st.floor_h); };
  const Vec3 n = f.normal();

  // Floors entirely inside [z0, z1] get windows.
  const int f_lo = std::max(0, int(std::ceil((z0 - st.grid_z) / st.floor_h - 1e-3f)));
  const int f_hi = int(std::floor((z1 - st.grid_z) / st.floor_h + 1e-3f));
  const bool windows = st.windows && f.length >= 0.6f * st.bay && f_hi > f_lo;
  if (!windows) {
    w.quad(f.at(0.0f, z0), f.at(f.length, z0), f.at(f.length, z1), f.at(0.0f, z1), n, uv(0.0f, z0), uv(f.length, z0),
           uv(f.length, z1), uv(0.0f, z1));
    return;
  }

  // Grid lines: columns 0 | window k left, right | ... | length; rows z0 | sill, lintel of floor f | ... | z1.
  // Cell (i, j) is a window opening when i and j are both odd.
  thread_local std::vector<float> xs, zs;
  xs.clear();
  zs.clear();
  xs.push_back(0.0f);
  for (int k = 0; k < bays; ++k) {
    xs.push_back((float(k) + kWindowU0) * bw);
    xs.push_back((float(k) + kWindowU1) * bw);
  }
  xs.push_back(f.length);
  zs.push_back(z0);
  for (int fl = f_lo; fl < f_hi; ++fl) {
    const float top = st.grid_z + float(fl + 1) * st.floor_h;
    zs.push_back(top - kWindowV1 * st.floor_h);
    zs.push_back(top - kWindowV0 * st.floor_h);
  }
  zs.push_back(z1);
  const uint32_t nx = uint32_t(xs.size()), nz = uint32_t(zs.size());
  const uint32_t base = uint32_t(w.mesh().positions.size());
  for (uint32_t j = 0; j < nz; ++j)
    for (uint32_t i = 0; i < nx; ++i) w.vertex(f.at(xs[i], zs[j]), n, uv(xs[i], zs[j]));
  // Counter-clockwise seen from outside: s grows to the viewer's right (WallFrame), z up.
  for (uint32_t j = 0; j + 1 < nz; ++j)
    for (uint32_t i = 0; i + 1 < nx; ++i) {
      if ((i & 1u) && (j & 1u)) continue;
      const uint32_t v00 = base + j * nx + i, v10 = v00 + 1, v01 = v00 + nx, v11 = v01 + 1;
      w.tri(v00, v10, v11);
      w.tri(v00, v11, v01);
    }

  const float r = st.recess;
  const Vec3 d = f.along();
  for (int fl = f_lo; fl < f_hi; ++fl) {
    const int row = 2 * (fl - f_lo) + 1;
    const float zb = zs[size_t(row)], zt = zs[size_t(row) + 1];
    const float floor_z = st.grid_z + float(fl) * st.floor_h;
    for (int k = 0; k < bays; ++k) {
      const float x0 = xs[size_t(2 * k + 1)], x1 = xs[size_t(2 * k + 2)];
      // Recess: glass at the back (textured with the tile's window), reveals around it.
      w.quad(f.at(x0, zb, -r), f.at(x1, zb, -r), f.at(x1, zt, -r), f.at(x0, zt, -r), n, uv(x0, zb), uv(x1, zb),
             uv(x1, zt), uv(x0, zt));
      const Vec2 du(r / bw, 0.0f), dv(0.0f, r / st.floor_h);
      w.quad(f.at(x0, zb), f.at(x1, zb), f.at(x1, zb, -r), f.at(x0, zb, -r), kUp, uv(x0, zb) + dv, uv(x1, zb) + dv,
             uv(x1, zb), uv(x0, zb));
      w.quad(f.at(x0, zt), f.at(x1, zt), f.at(x1, zt, -r), f.at(x0, zt, -r), -kUp, uv(x0, zt) - dv, uv(x1, zt) - dv,
             uv(x1, zt), uv(x0, zt));
      w.quad(f.at(x0, zb), f.at(x0, zb, -r), f.at(x0, zt, -r), f.at(x0, zt), d, uv(x0, zb) - du, uv(x0, zb), uv(x0, zt),
             uv(x0, zt) - du);
      w.quad(f.at(x1, zb), f.at(x1, zb, -r), f.at(x1, zt, -r), f.at(x1, zt), -d, uv(x1, zb) + du, uv(x1, zb),
             uv(x1, zt), uv(x1, zt) + du);

      if (st.frames) {
        // Frame: a ring 0.1 m wide standing 0.06 m proud of the wall, with its outer and inner sides.
        const float fw = 0.1f, fp = 0.06f;
        const float ox0 = x0 - fw, ox1 = x1 + fw, ozb = zb - fw, ozt = zt + fw;
        const Vec3 ob0 = f.at(ox0, ozb, fp), ob1 = f.at(ox1, ozb, fp), ot1 = f.at(ox1, ozt, fp),
                   ot0 = f.at(ox0, ozt, fp);
        const Vec3 ib0 = f.at(x0, zb, fp), ib1 = f.at(x1, zb, fp), it1 = f.at(x1, zt, fp), it0 = f.at(x0, zt, fp);
        w.quadUv(ob0, ob1, ib1, ib0, n, kFrameUv);
        w.quadUv(ib1, ob1, ot1, it1, n, kFrameUv);
        w.quadUv(it0, it1, ot1, ot0, n, kFrameUv);
        w.quadUv(ob0, ib0, it0, ot0, n, kFrameUv);
        // Outer sides.
        w.quadUv(f.at(ox0, ozb), f.at(ox1, ozb), ob1, ob0, -kUp, kFrameUv);
        w.quadUv(f.at(ox0, ozt), f.at(ox1, ozt), ot1, ot0, kUp, kFrameUv);
        w.quadUv(f.at(ox0, ozb), f.at(ox0, ozt), ot0, ob0, -d, kFrameUv);
        w.quadUv(f.at(ox1, ozb), f.at(ox1, ozt), ot1, ob1, d, kFrameUv);
        // Inner sides, continuing the reveals out to the frame's face.
        w.quadUv(f.at(x0, zb), f.at(x1, zb), ib1, ib0, kUp, kFrameUv);
        w.quadUv(f.at(x0, zt), f.at(x1, zt), it1, it0, -kUp, kFrameUv);
        w.quadUv(f.at(x0, zb), f.at(x0, zt), it0, ib0, d, kFrameUv);
        w.quadUv(f.at(x1, zb), f.at(x1, zt), it1, ib1, -d, kFrameUv);
        // Sill under the frame.
        wallBox(w, f, x0 - 0.2f, x1 + 0.2f, 0.0f, 0.16f, ozb - 0.08f, ozb, kPlasterUv);
      }
      if (st.mullions) {
        // A cross in the opening, standing 0.06 m in front of the glass.
        const float mw = 0.04f, mo0 = -r, mo1 = -r + 0.08f;
        const float xm = 0.5f * (x0 + x1), zm = zb + 0.62f * (zt - zb);
        wallBox(w, f, xm - mw, xm + mw, mo0, mo1, zb, zt, kFrameUv, false);
        wallBox(w, f, x0, x1, mo0, mo1, zm - mw, zm + mw, kFrameUv);
      }
      if (st.balconies && fl >= 1 && (k % 2 == 0)) {
        // Slab at the floor level and a railing 1 m high (double-sided panels).
        const float bs0 = std::max(0.0f, x0 - 0.35f), bs1 = std::min(f.length, x1 + 0.35f), depth = 1.2f;
        wallBox(w, f, bs0, bs1, 0.0f, depth, floor_z - 0.18f, floor_z, kPlasterUv);
        const float rz = floor_z + 1.0f, ro = depth - 0.05f;
        panel(w, f.at(bs0, floor_z, ro), f.at(bs1, floor_z, ro), f.at(bs1, rz, ro), f.at(bs0, rz, ro), n, kPlasterUv);
        panel(w, f.at(bs0, floor_z, 0.0f), f.at(bs0, floor_z, ro), f.at(bs0, rz, ro), f.at(bs0, rz, 0.0f), d,
              kPlasterUv);
        panel(w, f.at(bs1, floor_z, 0.0f), f.at(bs1, floor_z, ro), f.at(bs1, rz, ro), f.at(bs1, rz, 0.0f), d,
              kPlasterUv);
      }
    }
  }
}

// Vertex i of a polygon pushed outward along its two edges by per-edge distances (mitre join, limited to 4x the
// larger distance).
Vec2 offsetVertex(const Polygon2& p, size_t i, float d_prev, float d_next) {
  const size_t n = p.size();
  const Vec2 v = p[i];
  const Vec2 e0 = v - p[(i + n - 1) % n], e1 = p[(i + 1) % n] - v;
  const float l0 = glm::length(e0), l1 = glm::length(e1);
  if (l0 <= 0.0f || l1 <= 0.0f) return v;
  const Vec2 t0 = e0 / l0, t1 = e1 / l1;
  const Vec2 n0 = outwardNormal(t0), n1 = outwardNormal(t1);
  const float denom = cross2(t0, t1);
  Vec2 out;
  if (std::abs(denom) < 1e-4f) {
    out = v + 0.5f * (n0 * d_prev + n1 * d_next);
  } else {
    // Lines v + n0 d_prev + t0 s and v + n1 d_next + t1 u meet where s = cross(q1 - q0, t1) / cross(t0, t1).
    const Vec2 q0 = v + n0 * d_prev, q1 = v + n1 * d_next;
    out = q0 + t0 * (cross2(q1 - q0, t1) / denom);
  }
  const float limit = 4.0f * std::max(d_prev, d_next);
  const Vec2 off = out - v;
  const float len = glm::length(off);
  if (len > limit && len > 0.0f) out = v + off * (limit / len);
  return out;
}

// A horizontal band (ledge, cornice) around the exposed edges of a footprint, standing `dist` out of the walls,
// from z_lo to z_hi: front, top and bottom faces per exposed edge, closed at its ends against unexposed walls.
void emitBand(MeshWriter& w, const Polygon2& p, const std::vector<uint8_t>& exposed, float z_lo, float z_hi,
              float dist) {
  const size_t n = p.size();
  thread_local Polygon2 o;
  o.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const size_t prev = (i + n - 1) % n;
    o[i] = offsetVertex(p, i, exposed[prev] ? dist : 0.0f, exposed[i] ? dist : 0.0f);
  }
  auto at = [](const Vec2& v, float z) { return Vec3(v.x, v.y, z); };
  for (size_t i = 0; i < n; ++i) {
    if (!exposed[i]) continue;
    const size_t j = (i + 1) % n;
    const Vec2 e = p[j] - p[i];
    const float len = glm::length(e);
    if (len < 1e-3f) continue;
    const Vec2 dir = e / len;
    const Vec3 nrm(outwardNormal(dir), 0.0f);
    // uvs: the plaster row above the tile's window, repeating along the band every 3 m.
    const float u1 = len / 3.0f, va = kPlasterUv.lo.y, vb = kPlasterUv.hi.y;
    w.quad(at(o[i], z_lo), at(o[j], z_lo), at(o[j], z_hi), at(o[i], z_hi), nrm, Vec2(0.0f, vb), Vec2(u1, vb),
           Vec2(u1, va), Vec2(0.0f, va));
    w.quad(at(p[i], z_hi), at(p[j], z_hi), at(o[j], z_hi), at(o[i], z_hi), kUp, Vec2(0.0f, vb), Vec2(u1, vb),
           Vec2(u1, va), Vec2(0.0f, va));
    w.quad(at(p[i], z_lo), at(p[j], z_lo), at(o[j], z_lo), at(o[i], z_lo), -kUp, Vec2(0.0f, vb), Vec2(u1, vb),
           Vec2(u1, va), Vec2(0.0f, va));
    // End caps where the band meets an unexposed wall: in the plane of that wall.
    const size_t prev = (i + n - 1) % n, next = j;
    if (!exposed[prev]) {
      const Vec2 pe = p[i] - p[prev];
      const float pl = glm::length(pe);
      const Vec3 cn = pl > 0.0f ? Vec3(outwardNormal(pe / pl), 0.0f) : -Vec3(dir, 0.0f);
      w.quadUv(at(p[i], z_lo), at(o[i], z_lo), at(o[i], z_hi), at(p[i], z_hi), cn, kPlasterUv);
    }
    if (!exposed[next]) {
      const Vec2 ne = p[(next + 1) % n] - p[next];
      const float nl = glm::length(ne);
      const Vec3 cn = nl > 0.0f ? Vec3(outwardNormal(ne / nl), 0.0f) : Vec3(dir, 0.0f);
      w.quadUv(at(p[j], z_lo), at(o[j], z_lo), at(o[j], z_hi), at(p[j], z_hi), cn, kPlasterUv);
    }
  }
}

// Flat horizontal polygon at height z, facing up, uvs in metres / kRoofTile relative to its first vertex.
void emitFlat(MeshWriter& w, const Polygon2& p, float z) {
  if (p.size() < 3) return;
  const std::vector<uint32_t> tris = triangulatePolygon(p);
  const uint32_t base = uint32_t(w.mesh().positions.size());
  const Vec2 o = p[0];
  for (const Vec2& v : p) w.vertex(Vec3(v.x, v.y, z), kUp, (v - o) / kRoofTile);
  for (size_t t = 0; t + 2 < tris.size(); t += 3) w.tri(base + tris[t], base + tris[t + 1], base + tris[t + 2]);
}

// Pyramid (spire) from a CCW base polygon at z up to an apex; uvs in the windowless band left of the tile's
// window, repeating every 4 m up the slope.
void emitPyramid(MeshWriter& w, const Polygon2& p, float z, const Vec3& apex) {
  const size_t n = p.size();
  for (size_t i = 0; i < n; ++i) {
    const Vec3 a(p[i].x, p[i].y, z), b(p[(i + 1) % n].x, p[(i + 1) % n].y, z);
    Vec3 nrm = glm::cross(b - a, apex - a);
    const float len = glm::length(nrm);
    nrm = len > 0.0f ? nrm / len : kUp;
    const float slant = glm::length(apex - 0.5f * (a + b)) / kRoofTile;
    w.triangle(a, b, apex, nrm, Vec2(kSideBandU0, 0.0f), Vec2(kSideBandU1, 0.0f),
               Vec2(0.5f * (kSideBandU0 + kSideBandU1), -slant));
  }
}

// Horizontal ring between a CCW outer polygon and a CCW inner polygon with the same vertex count (setback roofs),
// textured with the windowless band of the tile.
void emitRing(MeshWriter& w, const Polygon2& outer, const Polygon2& inner, float z) {
  const size_t n = outer.size();
  for (size_t i = 0; i < n; ++i) {
    const size_t j = (i + 1) % n;
    const Vec3 a(outer[i].x, outer[i].y, z), b(outer[j].x, outer[j].y, z), c(inner[j].x, inner[j].y, z),
        d(inner[i].x, inner[i].y, z);
    w.quadUv(a, b, c, d, kUp, UvRect{{kSideBandU0, 0.0f}, {kSideBandU1, 1.0f}});
  }
}

FacadeStyle styleFor(const Building& b, int detail, float grid_z) {
  FacadeStyle st;
  st.grid_z = grid_z;
  st.floor_h = b.floor_height;
  st.bay = detail >= 4 ? 0.8f * b.bay_width : b.bay_width;
  st.windows = detail >= 2;
  st.frames = detail >= 3;
  st.mullions = detail >= 4;
  return st;
}

std::vector<uint8_t> exposedMask(const Building& b) {
  std::vector<uint8_t> m(b.footprint.size(), 1);
  for (size_t i = 0; i < m.size() && i < b.walls.size(); ++i) m[i] = b.walls[i] != WallKind::Party;
  return m;
}

// Ledges above the ground floor (detail 1-3) or at every floor (detail 4), and a cornice at the eaves.
void emitLedges(MeshWriter& w, const Polygon2& p, const std::vector<uint8_t>& exposed, float z0, float z1,
                float floor_h, int detail, const std::vector<uint8_t>* cornice_mask = nullptr) {
  if (detail < 1) return;
  const int floors = int((z1 - z0) / floor_h + 0.5f);
  const int every = detail >= 4 ? 1 : floors;  // only the first floor line below detail 4
  for (int fl = 1; fl < floors; ++fl) {
    if (fl != 1 && (fl % every) != 0) continue;
    const float z = z0 + float(fl) * floor_h;
    if (z > z1 - 1.0f) break;
    emitBand(w, p, exposed, z - 0.18f, z + 0.06f, 0.15f);
  }
  emitBand(w, p, cornice_mask ? *cornice_mask : exposed, z1 - 0.55f, z1, 0.4f);
}

void appendOrdinary(const Building& b, int detail, BuildingMeshes& out) {
  MeshWriter facades(out.facades), roofs(out.roofs);
  const Polygon2& p = b.footprint;
  const size_t n = p.size();
  const float z0 = b.base_z, z1 = b.base_z + b.height;
  const std::vector<uint8_t> exposed = exposedMask(b);
  const bool gable = b.roof == RoofShape::Gable && n == 4 && b.ridge_edge >= 0 && b.ridge_edge < 4;

  FacadeStyle st = styleFor(b, detail, z0);
  for (size_t i = 0; i < n; ++i) {
    FacadeStyle wall_st = st;
    if (!exposed[i]) wall_st.windows = wall_st.frames = wall_st.mullions = false;
    wall_st.balconies = detail >= 3 && b.balconies && b.walls[i] == WallKind::Street;
    emitWall(facades, p[i], p[(i + 1) % n], z0, z1, wall_st);
  }

  if (!gable) {
    emitLedges(facades, p, exposed, z0, z1, b.floor_height, detail);
    emitFlat(roofs, p, z1);
    return;
  }

  // Pitched roof: eaves along edges r and r + 2 (parallel), ridge between the midpoints of the other two edges.
  const int r = b.ridge_edge;
  const Vec2 e0 = p[size_t(r)], e1 = p[size_t(r + 1) % 4], e2 = p[size_t(r + 2) % 4], e3 = p[size_t(r + 3) % 4];
  const Vec2 m1 = 0.5f * (e1 + e2), m3 = 0.5f * (e3 + e0);
  const float zr = z1 + b.roof_rise;
  auto at = [](const Vec2& v, float z) { return Vec3(v.x, v.y, z); };
  // Gable ends (part of the facade).
  for (auto [a, c, m] : {std::tuple{e1, e2, m1}, std::tuple{e3, e0, m3}}) {
    const Vec2 e = c - a;
    const float len = glm::length(e);
    if (len <= 0.0f) continue;
    const Vec3 nrm(outwardNormal(e / len), 0.0f);
    const float v0 = -(z1 - z0) / b.floor_height, vr = -(zr - z0) / b.floor_height;
    facades.triangle(at(a, z1), at(c, z1), at(m, zr), nrm, Vec2(0.0f, v0), Vec2(len / b.bay_width, v0),
                     Vec2(0.5f * len / b.bay_width, vr));
  }
  std::vector<uint8_t> cornice = exposed;
  cornice[size_t(r + 1) % 4] = cornice[size_t(r + 3) % 4] = 0;
  emitLedges(facades, p, exposed, z0, z1, b.floor_height, detail, &cornice);
  // Slopes.
  for (auto [a, c, ma, mc] : {std::tuple{e0, e1, m3, m1}, std::tuple{e2, e3, m1, m3}}) {
    const Vec3 pa = at(a, z1), pc = at(c, z1), qc = at(mc, zr), qa = at(ma, zr);
    Vec3 nrm = glm::cross(pc - pa, qa - pa);
    const float len = glm::length(nrm);
    nrm = len > 0.0f ? nrm / len : kUp;
    if (nrm.z < 0.0f) nrm = -nrm;
    const float eave = glm::length(pc - pa) / kRoofTile, slant = glm::length(qa - pa) / kRoofTile;
    roofs.quad(pa, pc, qc, qa, nrm, Vec2(0.0f, slant), Vec2(eave, slant), Vec2(eave, 0.0f), Vec2(0.0f));
  }
}

Polygon2 scaledAbout(const Polygon2& p, const Vec2& c, float s) {
  Polygon2 q(p.size());
  for (size_t i = 0; i < p.size(); ++i) q[i] = c + (p[i] - c) * s;
  return q;
}

void appendTower(const Building& b, int detail, BuildingMeshes& out) {
  MeshWriter w(out.landmark);
  const Polygon2& p = b.footprint;
  const Vec2 c = polygonCentroid(p);
  const float H = b.top;
  // Tiers: (scale of the footprint, top as a share of the height); the last one carries the mast.
  const float scales[3] = {1.0f, 0.74f, 0.5f};
  const float tops[3] = {b.height / H, 0.74f, 0.9f};
  FacadeStyle st = styleFor(b, detail, b.base_z);
  float z_prev = b.base_z;
  for (int t = 0; t < 3; ++t) {
    const Polygon2 tier = scaledAbout(p, c, scales[t]);
    // Tier tops on whole floors so windows fill each tier.
    const float z_top = b.base_z + std::round(tops[t] * H / b.floor_height) * b.floor_height;
    for (size_t i = 0; i < tier.size(); ++i) emitWall(w, tier[i], tier[(i + 1) % tier.size()], z_prev, z_top, st);
    const std::vector<uint8_t> all(tier.size(), 1);
    if (detail >= 1) emitBand(w, tier, all, z_top - 0.8f, z_top, 0.5f);
    if (detail >= 4)
      emitBand(w, tier, all, z_prev + 0.5f * (z_top - z_prev) - 0.2f, z_prev + 0.5f * (z_top - z_prev) + 0.2f, 0.3f);
    const Polygon2 next = t < 2 ? scaledAbout(p, c, scales[t + 1]) : scaledAbout(p, c, 0.16f);
    emitRing(w, tier, next, z_top);
    z_prev = z_top;
    if (t == 2) emitPyramid(w, next, z_top, Vec3(c.x, c.y, b.base_z + H));
  }
}

void appendChurch(const Building& b, int detail, BuildingMeshes& out) {
  MeshWriter w(out.landmark);
  const Polygon2& p = b.footprint;  // c0 c1 c2 c3, edge 0 the long side
  const Vec2 c0 = p[0], c1 = p[1], c2 = p[2], c3 = p[3];
  const float length = glm::length(c1 - c0), width = glm::length(c3 - c0);
  const Vec2 u = (c1 - c0) / length;
  const float z0 = b.base_z, hn = b.height, rise = b.roof_rise;
  const float zn = z0 + hn, zr = zn + rise;
  auto at = [](const Vec2& v, float z) { return Vec3(v.x, v.y, z); };

  // Nave: from the tower (first `width` of the length) to the far end.
  const Vec2 n0 = c0 + u * width, n3 = c3 + u * width;
  FacadeStyle nave = styleFor(b, detail, z0);
  nave.floor_h = hn / 2.0f;
  nave.bay = 5.0f;
  emitWall(w, n0, c1, z0, zn, nave);
  emitWall(w, c1, c2, z0, zn, nave);
  emitWall(w, c2, n3, z0, zn, nave);
  const Vec2 m_end = 0.5f * (c1 + c2), m_tower = 0.5f * (n0 + n3);
  {
    const Vec2 e = c2 - c1;
    const Vec3 nrm(outwardNormal(e / glm::length(e)), 0.0f);
    w.triangle(at(c1, zn), at(c2, zn), at(m_end, zr), nrm, Vec2(0.0f, 0.0f), Vec2(width / 4.0f, 0.0f),
               Vec2(width / 8.0f, -rise / 4.0f));
  }
  const Polygon2 nave_fp = {n0, c1, c2, n3};
  if (detail >= 1) emitBand(w, nave_fp, {1, 0, 1, 0}, zn - 0.6f, zn, 0.45f);
  for (auto [a, c, ma, mc] : {std::tuple{n0, c1, m_tower, m_end}, std::tuple{c2, n3, m_end, m_tower}}) {
    const Vec3 pa = at(a, zn), pc = at(c, zn), qc = at(mc, zr), qa = at(ma, zr);
    Vec3 nrm = glm::normalize(glm::cross(pc - pa, qa - pa));
    if (nrm.z < 0.0f) nrm = -nrm;
    w.quad(pa, pc, qc, qa, nrm, Vec2(0.0f), Vec2(glm::length(pc - pa) / kRoofTile, 0.0f),
           Vec2(glm::length(pc - pa) / kRoofTile, glm::length(qa - pa) / kRoofTile),
           Vec2(0.0f, glm::length(qa - pa) / kRoofTile));
  }

  // Front tower with a spire.
  const Polygon2 tower = {c0, n0, n3, c3};
  const float zt = z0 + std::max(hn + rise + 14.0f, 0.45f * b.top);
  FacadeStyle tst = styleFor(b, detail, z0);
  tst.floor_h = 6.0f;
  tst.bay = width / 3.0f;
  for (size_t i = 0; i < 4; ++i) emitWall(w, tower[i], tower[(i + 1) % 4], z0, zt, tst);
  const std::vector<uint8_t> all(4, 1);
  if (detail >= 1) emitBand(w, tower, all, zt - 1.0f, zt, 0.5f);
  if (detail >= 3) emitBand(w, tower, all, zn - 0.6f, zn, 0.45f);
  const Vec2 tc = 0.25f * (c0 + n0 + n3 + c3);
  const Polygon2 spire_base = scaledAbout(tower, tc, 0.8f);
  emitRing(w, tower, spire_base, zt);
  emitPyramid(w, spire_base, zt, Vec3(tc.x, tc.y, z0 + b.top));
}

// ---------------------------------------------------------------------------------------------------------------
// Lots

// Removes near-duplicate vertices and merges collinear edges of the same kind, keeping walls[i] with edge i.
void cleanLot(Polygon2& p, std::vector<WallKind>& k) {
  bool changed = true;
  while (changed && p.size() >= 3) {
    changed = false;
    for (size_t i = 0; i < p.size() && p.size() >= 3; ++i) {
      const size_t n = p.size();
      const size_t j = (i + 1) % n;
      if (glm::length(p[j] - p[i]) < 0.05f) {
        // Edge i has no length: drop vertex j; edge i takes over edge j's end and kind.
        k[i] = k[j];
        p.erase(p.begin() + std::ptrdiff_t(j));
        k.erase(k.begin() + std::ptrdiff_t(j));
        changed = true;
        break;
      }
    }
    if (changed) continue;
    for (size_t i = 0; i < p.size() && p.size() >= 3; ++i) {
      const size_t n = p.size();
      const size_t prev = (i + n - 1) % n, next = (i + 1) % n;
      const DVec2 a(p[prev]), b(p[i]), c(p[next]);
      const DVec2 ab = b - a, bc = c - b;
      const double area2 = std::abs(cross2(ab, bc));
      const double scale = glm::length(ab) * glm::length(bc);
      const bool collinear = area2 <= 1e-4 * scale;
      const bool spike = collinear && glm::dot(ab, bc) < 0.0;
      if (spike || (collinear && k[prev] == k[i])) {
        // Vertex i goes; edge prev now runs to p[next].
        p.erase(p.begin() + std::ptrdiff_t(i));
        k.erase(k.begin() + std::ptrdiff_t(i));
        changed = true;
        break;
      }
    }
  }
}

struct Strip {
  std::vector<Vec2> dir, inward;
  std::vector<float> len, arc;  // arc[i]: perimeter position of vertex i; arc[n] = perimeter
  std::vector<float> q0, q1;    // inner edge i spans [q0, q1] in edge i's coordinate along dir
  Polygon2 inner;               // ring corner of each vertex (repeats where edges were swallowed)
  Polygon2 courtyard;           // inner without repeats
  float depth = 0.0f;
};

// Inner polygon of the lot ring: every edge's line moved inward by `depth`, consecutive lines intersected. An edge
// whose inner segment comes out reversed (a short edge between two corners that turn the same way, e.g. a chamfer
// at a junction) is swallowed: it is dropped and its neighbours' lines meet directly, as in a straight skeleton;
// its strip becomes a triangle ending in that meeting point. inner[i] is where vertex i's corner of the ring lies
// (the start of inner edge i, the end of inner edge i - 1), so inner edges may have zero length.
// Valid when at least three edges survive, the inner polygon is simple and counter-clockwise, and everything on
// it lies at least ~depth from the block boundary (so that strips of opposite sides do not overlap).
bool buildStrip(const Polygon2& p, float depth, Strip& s) {
  const size_t n = p.size();
  s.dir.resize(n);
  s.inward.resize(n);
  s.len.resize(n);
  s.arc.resize(n + 1);
  s.q0.resize(n);
  s.q1.resize(n);
  s.inner.resize(n);
  s.depth = depth;
  s.arc[0] = 0.0f;
  for (size_t i = 0; i < n; ++i) {
    const Vec2 e = p[(i + 1) % n] - p[i];
    s.len[i] = glm::length(e);
    if (s.len[i] <= 0.0f) return false;
    s.dir[i] = e / s.len[i];
    s.inward[i] = Vec2(-s.dir[i].y, s.dir[i].x);
    s.arc[i + 1] = s.arc[i] + s.len[i];
  }
  // Meeting point of the offset lines of edges a and b (b after a, possibly with swallowed edges between).
  auto meet = [&](size_t a, size_t b, DVec2& out) {
    const DVec2 ta(s.dir[a]), tb(s.dir[b]);
    const DVec2 qa = DVec2(p[a]) + DVec2(s.inward[a]) * double(depth);
    const DVec2 qb = DVec2(p[b]) + DVec2(s.inward[b]) * double(depth);
    const double denom = cross2(ta, tb);
    if (std::abs(denom) < 1e-6) {
      if (glm::dot(ta, tb) < 0.0) return false;  // anti-parallel: the block is thinner than twice the depth
      out = qb;                                  // collinear: the corner of b moved inward
      return true;
    }
    out = qa + ta * (cross2(qb - qa, tb) / denom);
    return true;
  };
  thread_local std::vector<size_t> active;
  thread_local std::vector<DVec2> start;  // start[k]: where active edge k's inner segment begins
  active.resize(n);
  for (size_t i = 0; i < n; ++i) active[i] = i;
  while (true) {
    const size_t m = active.size();
    if (m < 3) return false;
    start.resize(m);
    for (size_t k = 0; k < m; ++k)
      if (!meet(active[(k + m - 1) % m], active[k], start[k])) return false;
    // The most reversed inner segment, measured along its edge's direction.
    double worst = 0.0;
    size_t worst_k = m;
    for (size_t k = 0; k < m; ++k) {
      const double len = glm::dot(start[(k + 1) % m] - start[k], DVec2(s.dir[active[k]]));
      if (len <= 1e-6 && (worst_k == m || len < worst)) worst = len, worst_k = k;
    }
    if (worst_k == m) break;
    active.erase(active.begin() + std::ptrdiff_t(worst_k));
  }
  // Map back: vertex i's ring corner is the start of the first active edge at or after edge i.
  const size_t m = active.size();
  for (size_t k = 0; k < m; ++k) {
    const size_t first = active[(k + m - 1) % m] + 1;  // edges after the previous active edge ...
    for (size_t e = first;; ++e) {                     // ... up to and including active[k]
      s.inner[e % n] = Vec2(start[k]);
      if (e % n == active[k]) break;
    }
  }
  for (size_t i = 0; i < n; ++i) {
    s.q0[i] = glm::dot(s.inner[i] - p[i], s.dir[i]);
    s.q1[i] = glm::dot(s.inner[(i + 1) % n] - p[i], s.dir[i]);
  }
  // The courtyard: ring corners without repeats.
  Polygon2 court;
  court.reserve(n);
  for (const Vec2& v : s.inner)
    if (court.empty() || glm::length(v - court.back()) > 1e-3f) court.push_back(v);
  while (court.size() > 1 && glm::length(court.front() - court.back()) <= 1e-3f) court.pop_back();
  if (court.size() < 3 || signedArea(court) <= 0.0 || !isSimplePolygon(court)) return false;
  const double need = 0.97 * double(depth);
  for (size_t i = 0; i < court.size(); ++i) {
    const Vec2 a = court[i], b = court[(i + 1) % court.size()];
    for (int k = 0; k < 4; ++k) {
      const Vec2 q = a + (b - a) * (float(k) / 4.0f);
      if (!pointInPolygon(q, p) || distanceToBoundary(q, p) < need) return false;
    }
  }
  s.courtyard = std::move(court);
  return true;
}

struct ArcPoint {
  size_t edge;
  float t;  // along the edge
};

ArcPoint locate(const Strip& s, float c) {
  const size_t n = s.len.size();
  const float total = s.arc[n];
  c = std::fmod(c, total);
  if (c < 0.0f) c += total;
  size_t e = size_t(std::upper_bound(s.arc.begin(), s.arc.end(), c) - s.arc.begin());
  e = e == 0 ? 0 : e - 1;
  if (e >= n) e = n - 1;
  return {e, std::clamp(c - s.arc[e], 0.0f, s.len[e])};
}

float heightSample(Rng& rng, const LotOptions& o) {
  const float h = o.height_median * o.height_scale * std::exp(o.height_sigma * rng.normal());
  return std::clamp(h, o.height_min, o.height_max);
}

void finishBuilding(Building& b, Rng& rng, const LotOptions& o) {
  b.floor_height = rng.uniform(3.0f, 3.5f);
  const float h = heightSample(rng, o);
  const int floors = std::max(2, int(std::lround(h / b.floor_height)));
  b.height = float(floors) * b.floor_height;
  b.bay_width = rng.uniform(2.8f, 3.6f);
  b.balconies = rng.uniform() < 0.35f;
  b.top = b.height;
}

bool validFootprint(const Polygon2& p) { return p.size() >= 3 && signedArea(p) >= 12.0 && isSimplePolygon(p); }

}  // namespace

std::vector<uint32_t> triangulatePolygon(const Polygon2& polygon) {
  const size_t n = polygon.size();
  std::vector<uint32_t> out;
  if (n < 3) return out;
  out.reserve(3 * (n - 2));
  const bool ccw = signedArea(polygon) >= 0.0;
  std::vector<uint32_t> v(n);
  for (size_t i = 0; i < n; ++i) v[i] = uint32_t(ccw ? i : n - 1 - i);
  auto P = [&](uint32_t i) { return DVec2(polygon[i]); };
  auto orient = [](const DVec2& a, const DVec2& b, const DVec2& c) { return cross2(b - a, c - a); };
  size_t guard = 0;
  while (v.size() > 3 && guard < 4 * n * n) {
    ++guard;
    const size_t m = v.size();
    bool clipped = false;
    for (size_t i = 0; i < m; ++i) {
      const uint32_t ia = v[(i + m - 1) % m], ib = v[i], ic = v[(i + 1) % m];
      const DVec2 a = P(ia), b = P(ib), c = P(ic);
      if (orient(a, b, c) <= 0.0) continue;  // reflex or flat corner: not an ear
      bool blocked = false;
      for (size_t k = 0; k < m && !blocked; ++k) {
        const uint32_t iq = v[k];
        if (iq == ia || iq == ib || iq == ic) continue;
        const DVec2 q = P(iq);
        if (q == a || q == b || q == c) continue;
        blocked = orient(a, b, q) > 0.0 && orient(b, c, q) > 0.0 && orient(c, a, q) >= 0.0;
      }
      if (blocked) continue;
      out.push_back(ia);
      out.push_back(ib);
      out.push_back(ic);
      v.erase(v.begin() + std::ptrdiff_t(i));
      clipped = true;
      break;
    }
    if (!clipped) {
      // Only flat corners left (or rounding trouble): cut the least reflex corner so the loop ends.
      size_t best = 0;
      double best_o = -1e300;
      for (size_t i = 0; i < m; ++i) {
        const double o = orient(P(v[(i + m - 1) % m]), P(v[i]), P(v[(i + 1) % m]));
        if (o > best_o) best_o = o, best = i;
      }
      out.push_back(v[(best + m - 1) % m]);
      out.push_back(v[best]);
      out.push_back(v[(best + 1) % m]);
      v.erase(v.begin() + std::ptrdiff_t(best));
    }
  }
  if (v.size() == 3) {
    out.push_back(v[0]);
    out.push_back(v[1]);
    out.push_back(v[2]);
  }
  return out;
}

BlockLayout layoutBlock(const Polygon2& block_in, uint64_t seed, const LotOptions& o) {
  BlockLayout layout;
  Polygon2 block = cleanPolygon(block_in, 0.05f);
  if (block.size() < 3 || std::abs(signedArea(block)) < 1.0 || !isSimplePolygon(block)) return layout;
  makeCounterClockwise(block);
  Rng rng(seed);

  const double area = signedArea(block);
  float perimeter = 0.0f;
  for (size_t i = 0; i < block.size(); ++i) perimeter += glm::length(block[(i + 1) % block.size()] - block[i]);

  auto singleBuilding = [&]() {
    Building b;
    b.footprint = block;
    b.walls.assign(block.size(), WallKind::Street);
    finishBuilding(b, rng, o);
    layout.buildings.push_back(std::move(b));
    return layout;
  };
  if (area < o.single_building_area || perimeter < 2.0f * o.lot_width_min) return singleBuilding();

  // The ring of lots: shrink the depth until the inner polygon is valid.
  Strip s;
  bool ok = false;
  const float min_depth = 0.75f * o.lot_depth_min;
  for (float depth = rng.uniform(o.lot_depth_min, o.lot_depth_max); depth >= min_depth; depth *= 0.85f)
    if ((ok = buildStrip(block, depth, s))) break;
  if (!ok) return singleBuilding();
  layout.courtyard = s.courtyard;

  // Cuts along the perimeter, each lot lot_width_min..lot_width_max wide. A cut must be perpendicular to its
  // street: it may not fall in the wedge of a convex corner (before the inner edge starts or after it ends), or
  // the lots there would be slivers; such a cut moves forward to where the next inner edge starts, so the corner
  // lot takes the whole corner (a corner building).
  const size_t n = block.size();
  auto straighten = [&](float c) {
    for (size_t guard = 0; guard <= n; ++guard) {
      const ArcPoint ap = locate(s, c);
      const float lo = std::max(0.0f, s.q0[ap.edge]), hi = std::min(s.len[ap.edge], s.q1[ap.edge]);
      // A straight zone of at least half a metre (a swallowed edge has none).
      if (hi - lo >= 0.5f && ap.t <= hi) return ap.t < lo ? c + (lo - ap.t) : c;
      c += s.len[ap.edge] - ap.t + 1e-3f;  // past the end of this edge: on to the next one
    }
    return c;
  };
  std::vector<float> cuts;
  const float start = straighten(rng.uniform(0.0f, perimeter));
  cuts.push_back(start);
  const float end = start + perimeter;
  float pos = start;
  while (true) {
    const float next = straighten(pos + rng.uniform(o.lot_width_min, o.lot_width_max));
    if (end - next < o.lot_width_min) break;
    cuts.push_back(next);
    pos = next;
  }
  if (cuts.size() < 2) {
    const float half = straighten(start + 0.5f * perimeter);
    cuts.push_back(half < end - 1.0f ? half : start + 0.5f * perimeter);
  }
  cuts.push_back(end);

  auto outerPoint = [&](const ArcPoint& ap) { return block[ap.edge] + s.dir[ap.edge] * ap.t; };
  // The cut's inner end: straight across the strip where the inner edge runs alongside, else its nearer end
  // (a swallowed edge's inner edge is a single point).
  auto innerPoint = [&](const ArcPoint& ap) {
    const size_t e = ap.edge;
    const float span = s.q1[e] - s.q0[e];
    if (span <= 1e-6f) return s.inner[e];
    const float alpha = (std::clamp(ap.t, s.q0[e], s.q1[e]) - s.q0[e]) / span;
    return s.inner[e] + (s.inner[(e + 1) % n] - s.inner[e]) * alpha;
  };
  Polygon2 outer_chain, inner_chain;
  std::vector<size_t> corners;
  for (size_t k = 0; k + 1 < cuts.size(); ++k) {
    const float ca = cuts[k], cb = cuts[k + 1], span = cb - ca;
    const ArcPoint pa = locate(s, ca), pb = locate(s, cb);
    // Block corners strictly inside (ca, cb), in order.
    corners.clear();
    const float ca_mod = s.arc[pa.edge] + pa.t;
    for (size_t m = 1; m <= n; ++m) {
      const size_t j = (pa.edge + m) % n;
      float d = s.arc[j] - ca_mod;
      if (d < 0.0f) d += perimeter;
      if (d >= span - 1e-4f) break;
      if (d > 1e-4f) corners.push_back(j);
    }
    Building b;
    b.footprint.clear();
    b.footprint.push_back(outerPoint(pa));
    for (size_t j : corners) b.footprint.push_back(block[j]);
    b.footprint.push_back(outerPoint(pb));
    b.walls.assign(b.footprint.size() - 1, WallKind::Street);
    b.walls.push_back(WallKind::Party);
    b.footprint.push_back(innerPoint(pb));
    for (auto it = corners.rbegin(); it != corners.rend(); ++it) {
      b.footprint.push_back(s.inner[*it]);
      b.walls.push_back(WallKind::Courtyard);
    }
    b.footprint.push_back(innerPoint(pa));
    b.walls.push_back(WallKind::Courtyard);
    b.walls.push_back(WallKind::Party);
    FF_CHECK(b.walls.size() == b.footprint.size());
    cleanLot(b.footprint, b.walls);
    if (!validFootprint(b.footprint)) {
      ++layout.skipped_lots;
      continue;
    }
    finishBuilding(b, rng, o);
    // Pitched roof on a four-sided street lot whose street and courtyard edges are parallel.
    if (b.footprint.size() == 4 && b.height < 30.0f && rng.uniform() < o.gable_share) {
      for (int r = 0; r < 4; ++r) {
        if (b.walls[size_t(r)] != WallKind::Street || b.walls[size_t(r + 2) % 4] != WallKind::Courtyard) continue;
        const Vec2 d0 = glm::normalize(b.footprint[size_t(r + 1) % 4] - b.footprint[size_t(r)]);
        const Vec2 d2 = glm::normalize(b.footprint[size_t(r + 3) % 4] - b.footprint[size_t(r + 2) % 4]);
        if (std::abs(cross2(d0, d2)) > 0.01f || glm::dot(d0, d2) > 0.0f) continue;
        b.roof = RoofShape::Gable;
        b.ridge_edge = r;
        b.roof_rise = 0.5f * s.depth * std::tan(float(degToRad(rng.uniform(28.0f, 42.0f))));
        b.top = b.height + b.roof_rise;
        break;
      }
    }
    layout.buildings.push_back(std::move(b));
  }
  return layout;
}

std::optional<Building> makeLandmark(LandmarkKind kind, const Polygon2& block_in, uint64_t seed) {
  if (kind == LandmarkKind::None) return std::nullopt;
  Polygon2 block = cleanPolygon(block_in, 0.05f);
  if (block.size() < 3 || std::abs(signedArea(block)) < 1.0) return std::nullopt;
  makeCounterClockwise(block);
  Rng rng(seed);

  // The point deepest inside the block (sampled): the landmark's centre, with a circle of radius `room` free.
  const Box2 box = polygonBounds(block);
  Vec2 centre = polygonCentroid(block);
  double room = pointInPolygon(centre, block) ? distanceToBoundary(centre, block) : 0.0;
  const int samples = 24;
  for (int y = 0; y < samples; ++y)
    for (int x = 0; x < samples; ++x) {
      const Vec2 q = box.lo + box.extent() * Vec2((float(x) + 0.5f) / samples, (float(y) + 0.5f) / samples);
      if (!pointInPolygon(q, block)) continue;
      const double d = distanceToBoundary(q, block);
      if (d > room) room = d, centre = q;
    }
  // Orientation: along the block's longest edge.
  Vec2 axis(1.0f, 0.0f);
  float longest = 0.0f;
  for (size_t i = 0; i < block.size(); ++i) {
    const Vec2 e = block[(i + 1) % block.size()] - block[i];
    if (glm::length(e) > longest) longest = glm::length(e), axis = e / glm::length(e);
  }
  const Vec2 side(-axis.y, axis.x);
  const float fit = 0.95f * float(room);  // the footprint's half-diagonal must stay below this

  Building b;
  b.landmark = kind;
  auto rect = [&](float half_len, float half_wid) {
    return Polygon2{centre - axis * half_len - side * half_wid, centre + axis * half_len - side * half_wid,
                    centre + axis * half_len + side * half_wid, centre - axis * half_len + side * half_wid};
  };
  if (kind == LandmarkKind::Tower) {
    const float half = std::min(rng.uniform(11.0f, 16.0f), fit / std::sqrt(2.0f));
    if (half < 5.0f) return std::nullopt;
    b.footprint = rect(half, half);
    b.floor_height = 4.0f;
    b.bay_width = 3.2f;
    b.top = rng.uniform(130.0f, 190.0f);
    b.height = std::round(0.48f * b.top / b.floor_height) * b.floor_height;
  } else {
    float len = rng.uniform(45.0f, 65.0f), wid = 0.38f * len;
    const float half_diag = 0.5f * std::sqrt(len * len + wid * wid);
    if (half_diag > fit) {
      len *= fit / half_diag;
      wid *= fit / half_diag;
    }
    if (wid < 8.0f) return std::nullopt;
    b.footprint = rect(0.5f * len, 0.5f * wid);
    b.floor_height = 8.0f;
    b.bay_width = 5.0f;
    b.height = std::clamp(1.1f * wid, 12.0f, 22.0f);
    b.roof = RoofShape::Gable;
    b.roof_rise = 0.5f * wid;
    b.top = rng.uniform(95.0f, 120.0f);
  }
  b.walls.assign(b.footprint.size(), WallKind::Street);
  return b;
}

void appendBuildingGeometry(const Building& building, int detail, BuildingMeshes& out) {
  detail = std::clamp(detail, 0, 4);
  if (building.footprint.size() < 3) return;
  switch (building.landmark) {
    case LandmarkKind::Tower:
      appendTower(building, detail, out);
      break;
    case LandmarkKind::Church:
      appendChurch(building, detail, out);
      break;
    case LandmarkKind::None:
      appendOrdinary(building, detail, out);
      break;
  }
}

}  // namespace farfield::gen
