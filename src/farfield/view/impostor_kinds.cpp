#include "farfield/view/impostor_kinds.h"

#include <map>

#include "farfield/core/check.h"

namespace farfield::view {

const char* decisionName(size_t kind) {
  static const char* const kNames[kDecisionKinds] = {"impostor",         "as geometry", "unchecked", "dynamic",
                                                     "cluster impostor", "cluster as geometry"};
  return kind < kDecisionKinds ? kNames[kind] : "geometry";
}

Vec4 decisionTint(size_t kind) {
  switch (kind) {
    case 0: return {1.0f, 0.45f, 0.1f, 1.0f};   // impostor valid under the bound: orange
    case 2: return {1.0f, 0.12f, 0.12f, 1.0f};  // unchecked: red
    case 3: return {0.1f, 0.8f, 1.0f, 1.0f};    // dynamic: cyan
    case 4: return {0.9f, 0.2f, 1.0f, 1.0f};    // placed cluster: magenta
    default: return {1.0f, 1.0f, 1.0f, 1.0f};
  }
}

std::array<size_t, kDecisionKinds> countDecisions(const runtime::FramePlan& plan) {
  std::array<size_t, kDecisionKinds> counts{};
  for (const runtime::LayerDecision& d : plan.layers) ++counts[d.index()];
  return counts;
}

std::vector<size_t> itemKinds(const runtime::FramePlan& plan, const gpu::GpuScene& gpu_scene, uint32_t layer_id_base) {
  std::map<uint32_t, size_t> layer_kind;
  bool placed = false;
  for (const runtime::LayerDecision& d : plan.layers) {
    std::visit(
        [&](const auto& v) {
          using T = std::decay_t<decltype(v)>;
          if constexpr (std::is_same_v<T, runtime::ClusterAsImpostor> || std::is_same_v<T, runtime::ClusterAsGeometry>)
            placed = true;
          else
            layer_kind[v.layer] = d.index();
        },
        d);
  }
  const std::vector<gpu::GpuMesh>& meshes = gpu_scene.meshes();
  std::vector<size_t> kinds(plan.items.size(), kDecisionKinds);
  for (size_t i = 0; i < plan.items.size(); ++i) {
    const gpu::GpuMesh* mesh = plan.items[i].mesh;
    if (!meshes.empty() && mesh >= meshes.data() && mesh < meshes.data() + meshes.size()) continue;  // geometry
    if (placed) {
      kinds[i] = 4;
      continue;
    }
    const uint32_t id = plan.items[i].object_id;
    const auto it = id >= layer_id_base ? layer_kind.find(id - layer_id_base) : layer_kind.end();
    kinds[i] = it != layer_kind.end() ? it->second : 0;
  }
  return kinds;
}

std::vector<gpu::DrawItem> tintedItems(std::span<const gpu::DrawItem> items, std::span<const size_t> kinds,
                                       std::vector<gpu::GpuMaterial>& materials) {
  FF_CHECK(items.size() == kinds.size());
  materials.clear();
  materials.reserve(items.size());  // no reallocation: the items point into it
  std::vector<gpu::DrawItem> out(items.begin(), items.end());
  for (size_t i = 0; i < out.size(); ++i) {
    if (kinds[i] >= kDecisionKinds) continue;
    gpu::GpuMaterial material = out[i].material ? *out[i].material : gpu::GpuMaterial{};
    material.base_color *= decisionTint(kinds[i]);
    materials.push_back(material);
    out[i].material = &materials.back();
  }
  return out;
}

}  // namespace farfield::view
