// Lookups in the placement database's BSP of the view space: the leaf holding an eye, the CPV holding a view.
#include "farfield/store/placement_store.h"

#include <algorithm>
#include <optional>
#include <vector>

namespace farfield::store {

std::optional<uint32_t> lookupLeaf(const PlacementIndex& index, const Vec3& eye) {
  const std::vector<StoredViewSpaceNode>& nodes = index.nodes;
  if (nodes.empty() || !nodes[0].box.contains(eye)) return std::nullopt;
  size_t at = 0;
  while (nodes[at].children[0] >= 0) {
    const int lower = nodes[at].children[0], upper = nodes[at].children[1];
    // Guards for an index built in memory and never checked (a read index always passes them).
    if (lower <= int(at) || upper <= int(at) || size_t(lower) >= nodes.size() || size_t(upper) >= nodes.size())
      return std::nullopt;
    at = nodes[size_t(lower)].box.contains(eye) ? size_t(lower) : size_t(upper);
  }
  return uint32_t(at);
}

std::optional<uint32_t> lookupCpv(const PlacementIndex& index, const Vec3& eye, const Vec3& dir) {
  const std::optional<uint32_t> leaf = lookupLeaf(index, eye);
  return leaf ? cpvInLeaf(index, *leaf, eye, dir) : std::nullopt;
}

std::optional<uint32_t> cpvInLeaf(const PlacementIndex& index, uint32_t leaf_index, const Vec3& eye, const Vec3& dir) {
  if (leaf_index >= index.nodes.size()) return std::nullopt;
  const StoredViewSpaceNode& leaf = index.nodes[leaf_index];
  const uint64_t end = std::min<uint64_t>(uint64_t(leaf.cpv_first) + leaf.cpv_count, index.cpvs.size());
  for (uint64_t k = leaf.cpv_first; k < end; ++k)
    if (index.cpvs[k].region.contains(eye) && index.cpvs[k].vdi.contains(dir)) return uint32_t(k);
  return std::nullopt;
}

}  // namespace farfield::store
