// Problem view space approximation: conservative problem views (Jeschke et al. 2005, section 3).
//
// The user's view-space box is split by a regular binary space partition (midpoint of the longest axis) until the
// longest side of a region is <= min_region_size. For each region visited, view directions are subdivided from 360
// degrees: the six cube faces, then a quadtree per face (core/enclosing_frustum.h) down to `vdiLevels()` levels, and a
// VDI is refined only while its estimated time t_enc exceeds t_max. A VDI at the deepest level still over t_max holds
// a problem view. A region is split further only if it holds one (section 3: the 2D result terminates the 3D split),
// so areas that are fast from every direction are dropped early. In a region of minimum size each such VDI becomes a
// CPV; all CPVs have the same region size and the same VDI level ("equally sized").
//
// The time estimate is the caller's (a cost model over the region's enclosing frustum, see enclosingFrustum()), so
// this file needs no GPU. Units: metres, radians; times in the unit of t_max.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "farfield/core/bounds.h"
#include "farfield/core/camera.h"
#include "farfield/core/enclosing_frustum.h"

namespace farfield::placement {

struct ViewSpaceOptions {
  Box3 box;                                    // the view space V_3D; must not be empty
  float min_region_size = 23.0f;               // metres, > 0 (paper: 23 m)
  float min_vdi_angle = float(degToRad(11.25)); // radians, > 0: VDIs are refined until their width is <= this
  double t_max = 0.0;                          // > 0

  // Quadtree levels below a cube face: the smallest L with 90 degrees / 2^L <= min_vdi_angle (11.25 -> 3).
  int vdiLevels() const;
  // Throws farfield::Error naming the option.
  void validate() const;
};

// The caller's estimates. `visible_set` is optional: from-region visibility (section 3.1, observation 2.3), called
// once per region visited; its result is handed to `estimate` for that region and its VDIs (nullptr without it).
struct ViewSpaceCallbacks {
  std::function<std::vector<uint32_t>(const Box3& region)> visible_set;
  // Required: a conservative rendering time for every view with its eye in `region` and its direction in `vdi`
  // (t_enc of the enclosing frustum), finite and >= 0, in the unit of t_max.
  std::function<double(const Box3& region, const Vdi& vdi, const std::vector<uint32_t>* visible)> estimate;
};

struct Cpv {
  Box3 region;
  Vdi vdi;
  double t_enc = 0.0;  // > t_max
  int node = 0;        // index of its region in ViewSpace::nodes
};

// A region of the binary space partition that was visited. Children are -1 for a leaf; a leaf with cpv_count 0 has
// no problem view. The CPVs of a subtree are contiguous: [cpv_first, cpv_first + cpv_count).
struct ViewSpaceNode {
  Box3 box;
  int parent = -1;
  int children[2] = {-1, -1};
  int depth = 0;
  uint32_t cpv_first = 0;
  uint32_t cpv_count = 0;
};

struct ViewSpaceCounts {
  size_t regions = 0;          // regions visited
  size_t problem_regions = 0;  // minimum-size regions holding a CPV
  size_t estimates = 0;        // calls of `estimate`
  size_t cpvs = 0;
};

struct ViewSpace {
  ViewSpaceOptions options;
  std::vector<Cpv> cpvs;
  std::vector<ViewSpaceNode> nodes;  // nodes[0] is the whole box
  ViewSpaceCounts counts;

  // The CPV holding the view (eye, direction), or none (outside the box, or no problem there). `dir` non-zero.
  std::optional<uint32_t> lookup(const Vec3& eye, const Vec3& dir) const;
  std::optional<uint32_t> lookup(const Camera& camera) const { return lookup(camera.eye, camera.forward()); }
};

// Throws farfield::Error for bad options, a missing estimate, or an estimate that is negative or not finite.
ViewSpace approximateProblemViewSpace(const ViewSpaceOptions& options, const ViewSpaceCallbacks& callbacks);

// The regular partition the view space is split by, for callers that need its regions without a ViewSpace (the
// visibility cache, `place --visibility-only`). A region is a leaf when its longest side is <= min_size; otherwise
// it splits at the midpoint of its longest axis into {lower, upper}.
bool isPartitionLeaf(const Box3& region, float min_size);
std::array<Box3, 2> splitRegion(const Box3& region);
// Every leaf under `box`, lower halves first.
std::vector<Box3> partitionLeaves(const Box3& box, float min_size);
// The leaf under `box` holding `eye` (on a split plane: the lower half, as ViewSpace::lookup); none outside `box`.
std::optional<Box3> partitionLeafOf(const Box3& box, float min_size, const Vec3& eye);

}  // namespace farfield::placement
