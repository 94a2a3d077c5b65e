// Facades: walls with their window grid (recesses, frames, sills, mullions, balconies) and the horizontal bands
// (ledges, cornices) around a footprint's exposed edges.
#include <algorithm>
#include <cmath>
#include <vector>

#include "farfield/gen/building_parts.h"

namespace farfield::gen {

namespace {

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

}  // namespace

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

namespace {

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

}  // namespace

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

void emitLedges(MeshWriter& w, const Polygon2& p, const std::vector<uint8_t>& exposed, float z0, float z1,
                float floor_h, int detail, const std::vector<uint8_t>* cornice_mask) {
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

}  // namespace farfield::gen
