// Impostor candidates: object-hierarchy node x view cell (Jeschke et al. 2005, section 4; parameters of 6.2).
//
// For every node of the object hierarchy, shaft view cells (core/shaft.h, apex at the node's centre) around axes every
// `direction_step` about the vertical, with each apex angle and minimum distances node size * first_distance_factor *
// 2^k, k < distance_steps (paper: 11.25 / 22.5 / 45 / 90 degrees, 11.25 degree steps, 1 .. 2^10 times the node size).
// The axes are horizontal by default (`elevations` = {0}): for a view space near the ground a shaft opening sideways
// holds the street-level regions around a cluster; add negative elevations for views from above.
// Optionally, rectangular view cells: the regions of the view-space partition (section 4, test 13 of section 6).
//
// A candidate serves a CPV when its view cell contains the CPV's region (Shaft::containsBox, or the region lies in the
// box cell) and the node's bounds may be seen from it (they intersect the CPV's enclosing frustum). A candidate that
// serves no CPV, or whose cluster may intersect its view cell (Shaft::mayIntersectBox, box overlap), is dropped.
#pragma once

#include <cstdint>
#include <optional>
#include <variant>
#include <vector>

#include "farfield/core/bounds.h"
#include "farfield/core/enclosing_frustum.h"
#include "farfield/core/shaft.h"
#include "farfield/placement/object_hierarchy.h"
#include "farfield/placement/view_space.h"

namespace farfield::placement {

struct CandidateOptions {
  bool shafts = true;
  std::vector<float> apex_angles = {float(degToRad(11.25)), float(degToRad(22.5)), float(degToRad(45.0)),
                                    float(degToRad(90.0))};  // radians, each in (0, pi]
  float direction_step = float(degToRad(11.25));             // radians, in (0, 2 pi]
  std::vector<float> elevations = {0.0f};                    // radians, each in (-pi/2, pi/2)
  float first_distance_factor = 1.0f;                        // > 0
  int distance_steps = 11;                                   // >= 1
  // Among one node's shafts around one axis serving exactly the same CPVs keep only the one with the smallest apex
  // angle, then the largest minimum distance (the smallest cell; it needs the least impostor memory).
  bool drop_identical = true;
  bool rectangular_cells = false;  // also the view-space partition's regions as box cells
  bool box_leaves_only = false;    // box cells from the partition's leaves only (per-cell placement, test 14)
};

using ViewCell = std::variant<Shaft, Box3>;

struct Candidate {
  int node = 0;               // object-hierarchy node
  ViewCell cell;
  std::vector<uint32_t> cpvs; // served CPVs, ascending
};

struct CandidateCounts {
  size_t considered = 0;   // (node, view cell) pairs looked at
  size_t intersecting = 0; // dropped: the cluster may intersect the view cell
  size_t no_cpv = 0;       // dropped: serves no CPV
  size_t identical = 0;    // dropped by drop_identical
  size_t kept = 0;
};

struct CandidateSet {
  std::vector<Candidate> candidates;
  CandidateCounts counts;
};

// The CPVs' enclosing frusta, in CPV order (candidates and cost estimates both need them).
std::vector<Frustum> cpvFrusta(const ViewSpace& view_space, const Lens& lens);

// The shaft an impostor of the candidate is planned for: its own shaft, or for a box cell the shaft from the node's
// centre around the box (Shaft::enclosing: a layered plan that keeps the bound from it keeps it from the box). Empty
// for a box no convex shaft from the node's centre holds.
std::optional<Shaft> planningShaft(const Candidate& candidate, const ObjectHierarchy& hierarchy);

// Throws farfield::Error naming the option for bad options (and for a bad lens).
CandidateSet generateCandidates(const ObjectHierarchy& hierarchy, const ViewSpace& view_space, const Lens& lens,
                                const CandidateOptions& options = {});

}  // namespace farfield::placement
