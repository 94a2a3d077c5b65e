// Colour regions of a skinned model (Steed's lecture part 3, "Impostors are unflexible": 16 independent regions,
// each modulated per agent): which of the kColorRegions tints of an agent colours each triangle.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "farfield/scene/skin.h"

namespace farfield::scene {

// Regions from the file's primitives (each with its own material) when `primitive_of_triangle` names more than one:
// primitive p -> region p mod kColorRegions. Otherwise a deterministic split by the skeleton, so that one-material
// models (CesiumMan, Fox) still get body parts: each triangle's dominant joint (the largest weight summed over its
// three vertices, lowest joint index on ties); the joints that dominate some triangle, in joint order, are spread
// evenly over the regions (k-th of n -> region k * kColorRegions / n). Needs per-vertex joints and weights
// (validateSkinnedModel); primitive_of_triangle may be empty (one primitive).
std::vector<uint8_t> colorRegions(const SkinnedModel& model, std::span<const uint32_t> primitive_of_triangle);

}  // namespace farfield::scene
