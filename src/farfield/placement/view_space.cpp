// Problem view space approximation: conservative problem views (Jeschke et al. 2005, section 3).
#include "farfield/placement/view_space.h"

#include <cmath>
#include <string>

#include "farfield/core/error.h"

namespace farfield::placement {

namespace {

const char* const kWhat = "view space";

// Splits of the regular BSP until the longest side is <= min_size (every region at one depth has the same size).
int splitDepth(Vec3 extent, float min_size) {
  int depth = 0;
  while (true) {
    int axis = 0;
    for (int i = 1; i < 3; ++i)
      if (extent[i] > extent[axis]) axis = i;
    if (extent[axis] <= min_size) return depth;
    extent[axis] *= 0.5f;
    ++depth;
    if (depth > 60) return depth;
  }
}

class Approximation {
 public:
  Approximation(const ViewSpaceOptions& options, const ViewSpaceCallbacks& callbacks)
      : cb_(callbacks), levels_(options.vdiLevels()) {
    vs_.options = options;
  }

  ViewSpace run() {
    vs_.nodes.push_back({vs_.options.box});
    visit(0);
    vs_.counts.cpvs = vs_.cpvs.size();
    return std::move(vs_);
  }

 private:
  double estimate(const Box3& region, const Vdi& vdi, const std::vector<uint32_t>* visible) {
    ++vs_.counts.estimates;
    const double t = cb_.estimate(region, vdi, visible);
    if (!std::isfinite(t) || t < 0.0)
      throw Error(kWhat, "the time estimate returned " + std::to_string(t) + " (expected finite and >= 0)");
    return t;
  }

  // Section 3.2: refine while t_enc > t_max, down to the minimum VDI. With `collect` every problem VDI at the last
  // level becomes a CPV of `node`; without, the search stops at the first one (the region only needs a yes or no).
  bool refine(int node, const Box3& region, const Vdi& vdi, int level, const std::vector<uint32_t>* visible,
              bool collect) {
    const double t = estimate(region, vdi, visible);
    if (!(t > vs_.options.t_max)) return false;
    if (level == levels_) {
      if (collect) vs_.cpvs.push_back({region, vdi, t, node});
      return true;
    }
    bool any = false;
    for (const Vdi& child : vdi.split()) {
      if (refine(node, region, child, level + 1, visible, collect)) {
        any = true;
        if (!collect) return true;
      }
    }
    return any;
  }

  bool directions(int node, const Box3& region, const std::vector<uint32_t>* visible, bool collect) {
    bool any = false;
    for (int face = 0; face < 6; ++face) {
      if (refine(node, region, Vdi::fullFace(face), 0, visible, collect)) {
        any = true;
        if (!collect) return true;
      }
    }
    return any;
  }

  void visit(int node) {
    const Box3 box = vs_.nodes[size_t(node)].box;
    ++vs_.counts.regions;
    std::vector<uint32_t> visible;
    if (cb_.visible_set) visible = cb_.visible_set(box);
    const std::vector<uint32_t>* visible_ptr = cb_.visible_set ? &visible : nullptr;
    const uint32_t first = uint32_t(vs_.cpvs.size());
    vs_.nodes[size_t(node)].cpv_first = first;
    if (isPartitionLeaf(box, vs_.options.min_region_size)) {
      if (directions(node, box, visible_ptr, true)) ++vs_.counts.problem_regions;
    } else if (directions(node, box, visible_ptr, false)) {
      const std::array<Box3, 2> halves = splitRegion(box);
      const int depth = vs_.nodes[size_t(node)].depth + 1;
      for (int k = 0; k < 2; ++k) {
        const int child = int(vs_.nodes.size());
        vs_.nodes.push_back({halves[size_t(k)], node, {-1, -1}, depth});
        vs_.nodes[size_t(node)].children[k] = child;
      }
      visit(vs_.nodes[size_t(node)].children[0]);
      visit(vs_.nodes[size_t(node)].children[1]);
    }
    vs_.nodes[size_t(node)].cpv_count = uint32_t(vs_.cpvs.size()) - first;
  }

  const ViewSpaceCallbacks& cb_;
  const int levels_;
  ViewSpace vs_;
};

}  // namespace

int ViewSpaceOptions::vdiLevels() const {
  int levels = 0;
  while (levels < 20 && 0.5 * kPi / std::ldexp(1.0, levels) > double(min_vdi_angle) * (1.0 + 1e-6)) ++levels;
  return levels;
}

void ViewSpaceOptions::validate() const {
  if (box.empty() || !isFinite(box.lo) || !isFinite(box.hi)) throw Error(kWhat, "box is empty or not finite");
  if (!(min_region_size > 0.0f) || !std::isfinite(min_region_size))
    throw Error(kWhat, "min_region_size " + std::to_string(min_region_size) + " must be > 0");
  if (!(min_vdi_angle > 0.0f) || !std::isfinite(min_vdi_angle))
    throw Error(kWhat, "min_vdi_angle " + std::to_string(min_vdi_angle) + " must be > 0");
  if (!(t_max > 0.0) || !std::isfinite(t_max)) throw Error(kWhat, "t_max " + std::to_string(t_max) + " must be > 0");
  const int depth = splitDepth(box.extent(), min_region_size);
  if (depth > 40)
    throw Error(kWhat, "min_region_size " + std::to_string(min_region_size) + " gives 2^" + std::to_string(depth) +
                           " regions for this box (at most 2^40)");
}

bool isPartitionLeaf(const Box3& region, float min_size) {
  return region.extent()[region.longestAxis()] <= min_size;
}

std::array<Box3, 2> splitRegion(const Box3& region) {
  const int axis = region.longestAxis();
  const float mid = 0.5f * (region.lo[axis] + region.hi[axis]);
  std::array<Box3, 2> halves{region, region};
  halves[0].hi[axis] = mid;
  halves[1].lo[axis] = mid;
  return halves;
}

std::vector<Box3> partitionLeaves(const Box3& box, float min_size) {
  std::vector<Box3> leaves, stack{box};
  while (!stack.empty()) {
    const Box3 region = stack.back();
    stack.pop_back();
    if (isPartitionLeaf(region, min_size)) {
      leaves.push_back(region);
      continue;
    }
    const std::array<Box3, 2> halves = splitRegion(region);
    stack.push_back(halves[1]);
    stack.push_back(halves[0]);
  }
  return leaves;
}

std::optional<Box3> partitionLeafOf(const Box3& box, float min_size, const Vec3& eye) {
  if (!box.contains(eye) || !(min_size > 0.0f)) return std::nullopt;
  Box3 region = box;
  while (!isPartitionLeaf(region, min_size)) {
    const std::array<Box3, 2> halves = splitRegion(region);
    region = halves[0].contains(eye) ? halves[0] : halves[1];
  }
  return region;
}

ViewSpace approximateProblemViewSpace(const ViewSpaceOptions& options, const ViewSpaceCallbacks& callbacks) {
  options.validate();
  if (!callbacks.estimate) throw Error(kWhat, "no time estimate callback");
  return Approximation(options, callbacks).run();
}

std::optional<uint32_t> ViewSpace::lookup(const Vec3& eye, const Vec3& dir) const {
  if (nodes.empty() || !nodes[0].box.contains(eye)) return std::nullopt;
  int at = 0;
  while (nodes[size_t(at)].children[0] >= 0) {
    const int lower = nodes[size_t(at)].children[0];
    at = nodes[size_t(lower)].box.contains(eye) ? lower : nodes[size_t(at)].children[1];
  }
  const ViewSpaceNode& leaf = nodes[size_t(at)];
  for (uint32_t k = leaf.cpv_first; k < leaf.cpv_first + leaf.cpv_count; ++k)
    if (cpvs[k].vdi.contains(dir)) return k;
  return std::nullopt;
}

}  // namespace farfield::placement
