// The per-cell environment-map baseline of Jeschke et al. 2005, section 6, test 15, measured against a placement
// database: for the view cells where the placement found problem views (its minimum-size regions with CPVs), each
// cell's far field as layered environment maps (impostor/environment_map.h) and its near field as geometry, under the
// placement's own error bound, frames and cost profile. Cells without a problem view need no impostor in either
// method, so they count for neither.
//
// The far-field distance of a cell is the largest of `far_distances` for which every CPV of the cell is estimated at
// or under t_max: the cost profile's bound over the near-field objects of the cell's visible set that meet the CPV's
// enclosing frustum, plus the environment map's draw calls and quads, plus the fill of the layer quads that frustum
// meets through the profile's layered draw term, as placement charges its impostors' layers (before 2026-12-03 the
// layers' fill was not charged, and the baseline "solved" cells that way). That is the placement's own guarantee rule
// (bake/place.h), so both methods are compared at the same t_max; the largest such distance needs the fewest layers.
// A cell no distance solves takes the smallest and is counted as unsolved (the paper's environment maps carry no
// frame-time guarantee at all).
//
// Memory: each cell's six faces are captured on the GPU layer by layer (only the objects whose depth range meets the
// slab), every layer is cut to its data (impostor::cropLayered's rule) and the cropped atlases are counted: colour
// textures and quads, the placement's "colour" bytes. With `sample` > 0 a seeded random subset of the cells is
// captured and the total for all cells is estimated from their mean (with its standard error).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "farfield/core/bounds.h"
#include "farfield/core/enclosing_frustum.h"
#include "farfield/core/error_bound.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/cost_profile.h"
#include "farfield/impostor/environment_map.h"
#include "farfield/scene/scene.h"
#include "farfield/store/placement_store.h"

namespace farfield::eval {

// A view cell given by the caller (every cell of the view space, the paper's rule) with its visible set.
struct EnvMapCellInput {
  Box3 region;
  std::vector<uint32_t> visible;  // ascending object ids
};

struct EnvMapBaselineOptions {
  std::vector<double> far_distances = {50.0, 75.0, 100.0, 150.0, 200.0, 300.0, 400.0, 600.0};  // metres
  size_t sample = 0;        // cells captured; 0 = all
  // Not empty: these cells instead of the placement's problem cells (the paper covers every cell of the view space);
  // a cell whose region is a problem cell of the placement gets its CPVs, any other none (its distance is the
  // largest tried). Use one far-field distance with it for the paper's rule.
  std::vector<EnvMapCellInput> cells;
  uint32_t seed = 1;
  impostor::EnvMapOptions envmap;
  bool progress = true;
};

struct EnvMapCell {
  Box3 region;
  size_t cpvs = 0;
  double far_distance = 0.0;
  bool solved = false;            // every CPV at or under t_max with this distance
  double t_est_max_ms = 0.0;      // the slowest CPV's estimate with the environment map
  size_t visible_objects = 0, near_objects = 0, far_objects = 0;
  size_t faces = 0, layers = 0, draws = 0;
  uint64_t planned_bytes = 0;     // before cropping
  uint64_t bytes = 0;             // cropped: colour atlases and quads
  uint64_t stored_texels = 0, covered_texels = 0;
  double capture_s = 0.0;
};

struct EnvMapBaselineReport {
  double t_max_ms = 0.0;
  ErrorBound bound;
  size_t problem_cells = 0;       // the placement's minimum-size regions with CPVs
  size_t all_cells = 0;           // the cells the estimate is for (problem_cells, or EnvMapBaselineOptions::cells)
  std::vector<EnvMapCell> cells;  // the captured ones
  size_t unsolved = 0;
  double bytes_captured = 0.0;    // sum over `cells`
  double bytes_estimate = 0.0;    // for all cells: mean * all_cells (= bytes_captured without sampling)
  double bytes_stderr = 0.0;      // standard error of that estimate (0 without sampling)
  double placement_bytes = 0.0;   // the placement's impostors, colour textures and quads (ids left out)
  double placement_total_bytes = 0.0;  // ... as placed (ids included when it has them)
  double wall_s = 0.0;
  nlohmann::json toJson() const;
};

// Runs the baseline for the placement `index` of `scene` (its object ids), with the placement's frame (`bound`,
// `lens`), budget and profile. Makes `context` current. Throws farfield::Error for an index made for another scene
// (object count), an index without visible sets, no far-field distance, or bad environment-map options.
EnvMapBaselineReport runEnvMapBaseline(gpu::Context& context, const scene::Scene& scene,
                                       const gpu::CostProfile& profile, const store::PlacementIndex& index,
                                       const ErrorBound& bound, const Lens& lens, double t_max_ms,
                                       const EnvMapBaselineOptions& options);

}  // namespace farfield::eval
