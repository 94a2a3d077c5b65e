// Bounding-volume hierarchy over the objects of a scene (binned SAH build), with frustum and box queries.
#pragma once

#include <cstdint>
#include <vector>

#include "farfield/core/bounds.h"
#include "farfield/core/camera.h"
#include "farfield/scene/scene.h"

namespace farfield::scene {

class Bvh {
 public:
  struct Node {
    Box3 bounds;
    uint32_t first = 0;  // leaf: first index into item order; inner: index of the left child (right = left + 1)
    uint32_t count = 0;  // leaf: number of items (> 0); inner: 0
  };

  Bvh() = default;
  // Builds over the world bounds of the given objects; leaves hold at most max_leaf_size objects.
  explicit Bvh(const Scene& scene, int max_leaf_size = 4);
  explicit Bvh(const std::vector<Box3>& item_bounds, const std::vector<uint32_t>& item_ids, int max_leaf_size = 4);

  // Ids of the objects whose world bounds intersect the frustum (conservative), appended to out.
  void queryFrustum(const Frustum& frustum, std::vector<uint32_t>& out) const;
  // Ids of the objects whose world bounds overlap the box.
  void queryBox(const Box3& box, std::vector<uint32_t>& out) const;

  const std::vector<Node>& nodes() const { return nodes_; }
  size_t itemCount() const { return ids_.size(); }
  int depth() const;

 private:
  std::vector<Node> nodes_;
  std::vector<uint32_t> ids_;    // object ids in leaf order
  std::vector<Box3> bounds_;     // item bounds in leaf order
};

}  // namespace farfield::scene
