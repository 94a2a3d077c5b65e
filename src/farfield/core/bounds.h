// Axis-aligned boxes in 2D and 3D. An empty box has lo > hi; expanding it by a point makes it that point.
#pragma once

#include <algorithm>
#include <limits>

#include "farfield/core/math.h"

namespace farfield {

template <class V>
struct BoxT {
  V lo{std::numeric_limits<float>::max()};
  V hi{std::numeric_limits<float>::lowest()};

  static BoxT fromPoints(const V& a, const V& b) {
    BoxT box;
    box.expand(a);
    box.expand(b);
    return box;
  }
  bool empty() const {
    for (int i = 0; i < V::length(); ++i)
      if (lo[i] > hi[i]) return true;
    return false;
  }
  void expand(const V& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  void expand(const BoxT& b) {
    if (b.empty()) return;
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
  }
  V center() const { return (lo + hi) * 0.5f; }
  V extent() const { return empty() ? V(0.0f) : hi - lo; }
  bool contains(const V& p) const {
    for (int i = 0; i < V::length(); ++i)
      if (p[i] < lo[i] || p[i] > hi[i]) return false;
    return true;
  }
  bool overlaps(const BoxT& b) const {
    for (int i = 0; i < V::length(); ++i)
      if (b.hi[i] < lo[i] || b.lo[i] > hi[i]) return false;
    return true;
  }
  int longestAxis() const {
    V e = extent();
    int axis = 0;
    for (int i = 1; i < V::length(); ++i)
      if (e[i] > e[axis]) axis = i;
    return axis;
  }
};

using Box2 = BoxT<Vec2>;
using Box3 = BoxT<Vec3>;

inline float surfaceArea(const Box3& b) {
  if (b.empty()) return 0.0f;
  Vec3 e = b.extent();
  return 2.0f * (e.x * e.y + e.y * e.z + e.z * e.x);
}

// Box enclosing the 8 transformed corners of b.
inline Box3 transformBox(const Box3& b, const Mat4& m) {
  Box3 out;
  if (b.empty()) return out;
  for (int i = 0; i < 8; ++i) {
    Vec3 c((i & 1) ? b.hi.x : b.lo.x, (i & 2) ? b.hi.y : b.lo.y, (i & 4) ? b.hi.z : b.lo.z);
    out.expand(Vec3(m * Vec4(c, 1.0f)));
  }
  return out;
}

}  // namespace farfield
