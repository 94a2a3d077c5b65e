// Object set hierarchy for impostor candidates (Jeschke et al. 2005, section 2.3; 9 levels in section 6.2).
#include "farfield/placement/object_hierarchy.h"

#include <algorithm>
#include <string>

#include "farfield/core/error.h"

namespace farfield::placement {

ObjectHierarchy ObjectHierarchy::build(const std::vector<HierarchyItem>& items, const HierarchyOptions& options) {
  if (options.max_levels < 1)
    throw Error("object hierarchy", "max_levels " + std::to_string(options.max_levels) + " must be >= 1");
  if (options.min_objects_to_split < 2)
    throw Error("object hierarchy", "min_objects_to_split " + std::to_string(options.min_objects_to_split) + " must be >= 2");
  ObjectHierarchy h;
  std::vector<uint32_t> index;  // into items, in leaf order
  for (uint32_t i = 0; i < items.size(); ++i) {
    const Box3& b = items[i].bounds;
    if (b.empty() || !isFinite(b.lo) || !isFinite(b.hi)) ++h.skipped_;
    else index.push_back(i);
  }
  if (index.empty()) return h;

  h.nodes_.push_back({});
  h.nodes_[0].count = uint32_t(index.size());
  // Nodes are appended in breadth-first order, so a node's children come after it and each level is contiguous.
  for (size_t n = 0; n < h.nodes_.size(); ++n) {
    const uint32_t first = h.nodes_[n].first, count = h.nodes_[n].count;
    Box3 bounds, centres;
    uint64_t triangles = 0;
    for (uint32_t k = first; k < first + count; ++k) {
      bounds.expand(items[index[k]].bounds);
      centres.expand(items[index[k]].bounds.center());
      triangles += items[index[k]].triangles;
    }
    h.nodes_[n].bounds = bounds;
    h.nodes_[n].triangles = triangles;
    if (h.nodes_[n].level + 1 >= options.max_levels || count < uint32_t(options.min_objects_to_split)) continue;
    // Median split on the centres along their longest axis (ties by id, so the build is deterministic).
    const int axis = centres.longestAxis();
    const uint32_t mid = first + count / 2;
    std::nth_element(index.begin() + first, index.begin() + mid, index.begin() + first + count,
                     [&](uint32_t a, uint32_t b) {
                       const float ca = items[a].bounds.center()[axis], cb = items[b].bounds.center()[axis];
                       return ca < cb || (ca == cb && items[a].id < items[b].id);
                     });
    for (int k = 0; k < 2; ++k) {
      HierarchyNode child;
      child.parent = int(n);
      child.level = h.nodes_[n].level + 1;
      child.first = k == 0 ? first : mid;
      child.count = k == 0 ? mid - first : first + count - mid;
      h.nodes_[n].children[k] = int(h.nodes_.size());
      h.nodes_.push_back(child);
    }
  }
  h.order_.reserve(index.size());
  for (uint32_t i : index) h.order_.push_back(items[i].id);
  return h;
}

ObjectHierarchy ObjectHierarchy::build(const scene::Scene& scene, const HierarchyOptions& options) {
  std::vector<HierarchyItem> items;
  items.reserve(scene.objects.size());
  for (const scene::Object& o : scene.objects) {
    uint64_t triangles = 0;
    for (const scene::Part& part : o.parts)
      if (part.mesh < scene.meshes.size()) triangles += scene.meshes[part.mesh].triangleCount();
    items.push_back({o.id, o.world_bounds, triangles});
  }
  return build(items, options);
}

std::span<const uint32_t> ObjectHierarchy::objects(int node) const {
  const HierarchyNode& n = nodes_.at(size_t(node));
  return std::span<const uint32_t>(order_.data() + n.first, n.count);
}

bool ObjectHierarchy::isAncestor(int a, int b) const {
  // Object ranges nest along the tree, and every node holds at least one object.
  const HierarchyNode& na = nodes_.at(size_t(a));
  const HierarchyNode& nb = nodes_.at(size_t(b));
  return na.level < nb.level && na.first <= nb.first && nb.first + nb.count <= na.first + na.count;
}

std::vector<int> ObjectHierarchy::parents() const {
  std::vector<int> p;
  p.reserve(nodes_.size());
  for (const HierarchyNode& n : nodes_) p.push_back(n.parent);
  return p;
}

float ObjectHierarchy::size(int node) const { return glm::length(nodes_.at(size_t(node)).bounds.extent()); }

}  // namespace farfield::placement
