// Reads a skinned, animated glTF 2.0 model (.glb or .gltf) into a SkinnedModel: the first mesh node that has a skin
// (all its triangle primitives merged), the skin's joints and inverse bind matrices, the node hierarchy and every
// animation. Y-up files are turned to Z up by Skeleton::root.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "farfield/scene/skin.h"

namespace farfield::scene {

// Defects of real skinned models that the import fixed and counted (DESIGN.md: counted warnings).
struct SkinImportStats {
  size_t renormalised_vertices = 0;   // weights not summing to 1 (within 1e-3), divided by their sum
  bool identity_inverse_bind = false;  // the skin had no inverseBindMatrices: identity (the glTF default) used
  size_t cubic_channels = 0;           // CUBICSPLINE channels sampled linearly through their values
  size_t skipped_channels = 0;         // channels of weights (morph targets) or of nodes outside the file, ignored
  size_t skipped_primitives = 0;       // primitives that are not triangles, or without joints and weights
  // One line per kind of defect ("12 vertices: skin weights renormalised"); empty when the import was clean.
  std::vector<std::string> warnings() const;
};

// Throws farfield::Error naming the file for: a missing or corrupt file, no skinned mesh, accessors out of range
// or truncated, joint indices out of range, non-finite or negative weights, weights summing to 0, inverse bind
// matrices too few or not finite, animation keys not increasing or of the wrong type (see validateSkinnedModel).
SkinnedModel importSkinnedModel(const std::string& path, SkinImportStats* stats = nullptr);

}  // namespace farfield::scene
