// Object set hierarchy for impostor candidates (Jeschke et al. 2005, section 2.3, observation 2.1; 9 levels in 6.2).
//
// A binary bounding-volume hierarchy over whole objects that clusters close objects first: each node's objects are
// split at the median of their bounds' centres along the longest axis of those centres, so the tree is balanced and
// `max_levels` bounds its depth exactly (the paper's fixed number of levels), unlike scene::Bvh, whose SAH build
// stops at a leaf size and does not expose the objects under an inner node. Every node is a candidate object
// cluster; the clusters of two nodes are either nested or disjoint (section 5.5 relies on this).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "farfield/core/bounds.h"
#include "farfield/scene/scene.h"

namespace farfield::placement {

struct HierarchyItem {
  uint32_t id = 0;         // object id (scene::Object::id)
  Box3 bounds;             // world bounds; an empty or non-finite box is skipped (counted)
  uint64_t triangles = 0;
};

struct HierarchyOptions {
  int max_levels = 9;           // levels including the root, >= 1
  int min_objects_to_split = 2; // a node with fewer objects is a leaf, >= 2
};

struct HierarchyNode {
  Box3 bounds;
  int parent = -1;
  int children[2] = {-1, -1};  // both -1 for a leaf
  int level = 0;               // root 0
  uint32_t first = 0;          // objects: ObjectHierarchy::objects(node) = order[first, first + count)
  uint32_t count = 0;
  uint64_t triangles = 0;
};

class ObjectHierarchy {
 public:
  // Throws farfield::Error for max_levels < 1 or min_objects_to_split < 2. No usable item gives an empty hierarchy.
  static ObjectHierarchy build(const std::vector<HierarchyItem>& items, const HierarchyOptions& options = {});
  // Items from the scene's objects (world bounds, triangles of all parts).
  static ObjectHierarchy build(const scene::Scene& scene, const HierarchyOptions& options = {});

  const std::vector<HierarchyNode>& nodes() const { return nodes_; }
  // Ids of the objects under a node.
  std::span<const uint32_t> objects(int node) const;
  // Node a is a strict ancestor of node b.
  bool isAncestor(int a, int b) const;
  // Parent index per node (-1 for the root), the shape placeGreedy takes.
  std::vector<int> parents() const;
  // Diagonal of the node's bounds, metres: the "object size" of section 6.2.
  float size(int node) const;
  size_t skipped() const { return skipped_; }

 private:
  std::vector<HierarchyNode> nodes_;
  std::vector<uint32_t> order_;
  size_t skipped_ = 0;
};

}  // namespace farfield::placement
