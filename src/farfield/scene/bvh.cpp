// Bounding-volume hierarchy over object bounds: binned surface-area-heuristic build, frustum and box queries.
#include "farfield/scene/bvh.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "farfield/core/check.h"

namespace farfield::scene {

namespace {

constexpr int kBins = 16;

bool finiteBox(const Box3& b) { return isFinite(b.lo) && isFinite(b.hi); }

// True when every point of the box is on the inner side of all six planes (its nearest corner is inside).
bool frustumContains(const Frustum& f, const Box3& box) {
  for (const Vec4& p : f.planes) {
    const Vec3 v(p.x >= 0 ? box.lo.x : box.hi.x, p.y >= 0 ? box.lo.y : box.hi.y, p.z >= 0 ? box.lo.z : box.hi.z);
    if (glm::dot(Vec3(p), v) + p.w < 0.0f) return false;
  }
  return true;
}

}  // namespace

Bvh::Bvh(const Scene& scene, int max_leaf_size) {
  std::vector<Box3> boxes;
  std::vector<uint32_t> ids;
  boxes.reserve(scene.objects.size());
  ids.reserve(scene.objects.size());
  for (const Object& o : scene.objects) {
    boxes.push_back(o.world_bounds);
    ids.push_back(o.id);
  }
  *this = Bvh(boxes, ids, max_leaf_size);
}

Bvh::Bvh(const std::vector<Box3>& item_bounds, const std::vector<uint32_t>& item_ids, int max_leaf_size) {
  FF_CHECK(item_bounds.size() == item_ids.size());
  const uint32_t leaf_max = uint32_t(std::max(1, max_leaf_size));

  // Items with empty (or non-finite) bounds can intersect nothing; they are left out so that they neither widen
  // nodes nor give meaningless centroids. Queries would never return them anyway.
  std::vector<uint32_t> order;
  std::vector<Vec3> centroids(item_bounds.size());
  order.reserve(item_bounds.size());
  for (uint32_t i = 0; i < item_bounds.size(); ++i)
    if (!item_bounds[i].empty() && finiteBox(item_bounds[i])) {
      order.push_back(i);
      centroids[i] = item_bounds[i].center();
    }
  if (order.empty()) return;

  struct Task {
    uint32_t node, begin, end;
  };
  nodes_.reserve(2 * order.size() / leaf_max + 1);
  nodes_.push_back({});
  std::vector<Task> stack{{0, 0, uint32_t(order.size())}};
  while (!stack.empty()) {
    const Task task = stack.back();
    stack.pop_back();
    Box3 bounds, centroid_bounds;
    for (uint32_t k = task.begin; k < task.end; ++k) {
      bounds.expand(item_bounds[order[k]]);
      centroid_bounds.expand(centroids[order[k]]);
    }
    nodes_[task.node].bounds = bounds;
    const uint32_t count = task.end - task.begin;
    if (count <= leaf_max) {
      nodes_[task.node].first = task.begin;
      nodes_[task.node].count = count;
      continue;
    }

    // Binned SAH: centroids are dropped into kBins slabs per axis; each of the kBins - 1 slab boundaries is a
    // candidate split whose cost is area(left) * n(left) + area(right) * n(right). The node is always split
    // (leaves hold at most max_leaf_size items), so only the best candidate matters, not the leaf cost.
    float best_cost = std::numeric_limits<float>::infinity();
    int best_axis = -1, best_split = 0;
    const Vec3 cext = centroid_bounds.extent();
    for (int axis = 0; axis < 3; ++axis) {
      if (!(cext[axis] > 0.0f)) continue;
      std::array<Box3, kBins> bin_box{};
      std::array<uint32_t, kBins> bin_count{};
      const float scale = float(kBins) / cext[axis];
      for (uint32_t k = task.begin; k < task.end; ++k) {
        const uint32_t i = order[k];
        const int b = std::min(kBins - 1, int((centroids[i][axis] - centroid_bounds.lo[axis]) * scale));
        bin_box[b].expand(item_bounds[i]);
        ++bin_count[b];
      }
      // Sweep from the right to get the right-hand areas, then from the left.
      std::array<float, kBins> right_area{};
      std::array<uint32_t, kBins> right_count{};
      Box3 acc;
      uint32_t n = 0;
      for (int b = kBins - 1; b > 0; --b) {
        acc.expand(bin_box[b]);
        n += bin_count[b];
        right_area[b] = surfaceArea(acc);
        right_count[b] = n;
      }
      acc = Box3{};
      n = 0;
      for (int s = 1; s < kBins; ++s) {  // split between bins s - 1 and s
        acc.expand(bin_box[s - 1]);
        n += bin_count[s - 1];
        if (n == 0 || right_count[s] == 0) continue;
        const float cost = surfaceArea(acc) * float(n) + right_area[s] * float(right_count[s]);
        if (cost < best_cost) {
          best_cost = cost;
          best_axis = axis;
          best_split = s;
        }
      }
    }

    uint32_t mid = task.begin;
    if (best_axis >= 0) {
      const float scale = float(kBins) / cext[best_axis];
      const float lo = centroid_bounds.lo[best_axis];
      auto* it = std::partition(order.data() + task.begin, order.data() + task.end, [&](uint32_t i) {
        return std::min(kBins - 1, int((centroids[i][best_axis] - lo) * scale)) < best_split;
      });
      mid = uint32_t(it - order.data());
    }
    if (mid == task.begin || mid == task.end) {
      // All centroids coincide (or binning could not separate them): split the range in half along the longest
      // axis so that leaves still respect max_leaf_size.
      const int axis = centroid_bounds.longestAxis();
      mid = task.begin + count / 2;
      std::nth_element(order.data() + task.begin, order.data() + mid, order.data() + task.end,
                       [&](uint32_t a, uint32_t b) { return centroids[a][axis] < centroids[b][axis]; });
    }

    const uint32_t left = uint32_t(nodes_.size());
    nodes_.push_back({});
    nodes_.push_back({});
    nodes_[task.node].first = left;
    nodes_[task.node].count = 0;
    stack.push_back({left + 1, mid, task.end});
    stack.push_back({left, task.begin, mid});
  }

  ids_.resize(order.size());
  bounds_.resize(order.size());
  for (size_t k = 0; k < order.size(); ++k) {
    ids_[k] = item_ids[order[k]];
    bounds_[k] = item_bounds[order[k]];
  }
}

void Bvh::queryFrustum(const Frustum& frustum, std::vector<uint32_t>& out) const {
  if (nodes_.empty()) return;
  // Each stack entry carries whether its node is already known to lie wholly inside the frustum; then nothing
  // below it needs testing (every item box inside passes Frustum::intersects too).
  std::vector<std::pair<uint32_t, bool>> stack{{0u, false}};
  while (!stack.empty()) {
    auto [index, inside] = stack.back();
    stack.pop_back();
    const Node& node = nodes_[index];
    if (!inside) {
      if (!frustum.intersects(node.bounds)) continue;
      inside = frustumContains(frustum, node.bounds);
    }
    if (node.count > 0) {
      for (uint32_t k = node.first; k < node.first + node.count; ++k)
        if (inside || frustum.intersects(bounds_[k])) out.push_back(ids_[k]);
    } else {
      stack.push_back({node.first + 1, inside});
      stack.push_back({node.first, inside});
    }
  }
}

void Bvh::queryBox(const Box3& box, std::vector<uint32_t>& out) const {
  if (nodes_.empty() || box.empty()) return;
  std::vector<uint32_t> stack{0};
  while (!stack.empty()) {
    const Node& node = nodes_[stack.back()];
    stack.pop_back();
    if (!node.bounds.overlaps(box)) continue;
    if (node.count > 0) {
      for (uint32_t k = node.first; k < node.first + node.count; ++k)
        if (bounds_[k].overlaps(box)) out.push_back(ids_[k]);
    } else {
      stack.push_back(node.first + 1);
      stack.push_back(node.first);
    }
  }
}

int Bvh::depth() const {
  if (nodes_.empty()) return 0;
  int deepest = 0;
  std::vector<std::pair<uint32_t, int>> stack{{0u, 1}};
  while (!stack.empty()) {
    auto [index, d] = stack.back();
    stack.pop_back();
    deepest = std::max(deepest, d);
    const Node& node = nodes_[index];
    if (node.count == 0) {
      stack.push_back({node.first, d + 1});
      stack.push_back({node.first + 1, d + 1});
    }
  }
  return deepest;
}

}  // namespace farfield::scene
