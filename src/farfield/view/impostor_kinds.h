// What a walkthrough frame drew, by kind: the plan's per-layer decisions counted (the panel's "impostors drawn by
// kind") and its draw items classified for the tint overlay (each impostor item drawn with its kind's colour
// multiplied into its material; geometry untouched).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "farfield/core/math.h"
#include "farfield/gpu/renderer.h"
#include "farfield/runtime/walkthrough.h"

namespace farfield::view {

// One per alternative of runtime::LayerDecision, in its order.
inline constexpr size_t kDecisionKinds = std::variant_size_v<runtime::LayerDecision>;
// "impostor", "as geometry", "unchecked", "dynamic", "cluster impostor", "cluster as geometry"
const char* decisionName(size_t kind);
// The tint of an impostor item of that kind (geometry kinds: white).
Vec4 decisionTint(size_t kind);

// How many of the plan's decisions are of each kind.
std::array<size_t, kDecisionKinds> countDecisions(const runtime::FramePlan& plan);

// For each item of the plan: kDecisionKinds for geometry (its mesh is one of gpu_scene's), else the kind of the
// decision that drew it (mmi: the decision of its layer, whose items carry object id layer_id_base + layer; placed:
// a cluster impostor).
std::vector<size_t> itemKinds(const runtime::FramePlan& plan, const gpu::GpuScene& gpu_scene, uint32_t layer_id_base);

// The items with every impostor item's material replaced by a copy whose base colour is multiplied by its kind's
// tint. `materials` holds the copies (the returned items point into it; keep it alive while drawing).
std::vector<gpu::DrawItem> tintedItems(std::span<const gpu::DrawItem> items, std::span<const size_t> kinds,
                                       std::vector<gpu::GpuMaterial>& materials);

}  // namespace farfield::view
