// Bake-time validity regions of a street cell's impostors (DESIGN.md, "the two promises": each impostor carries the
// viewpoints where its reprojection error stays under the bound, computed at bake time and never guessed at run
// time). See impostor/validity.h for the region and the per-object closed form.
//
// The error of an impostor captured from E (the cell's start at eye height), seen from a viewpoint V, is bounded by
// the largest of three terms:
//   - per object: impostor::parallaxBound(E, V, bounds), which covers what the capture could not hold: the parts of
//     the object hidden or seen at a grazing angle from E (its side faces, which a lateral step reveals) lie on
//     capture rays inside its bounds, behind the captured surface. The brute-force test of this file fails without
//     it (30 px at 20 m along and 5 m across the constructed street's cell, where the mesh terms alone said 10);
//   - per mesh triangle: impostor::triangleErrorBound(E, V, ...) over impostor::triangleErrors(), the parallax
//     between where a texel is drawn (its capture ray meets the triangle) and where what it shows lies;
//   - between objects of one impostor (rubber sheets and de-occlusion between them): Decoret et al.'s
//     visibility-event weight of the pair for the segment [E, V] (urban::computeEventGraph), the largest change of
//     the pair's relative angle while the viewer moves from E to V, with the paper's closed forms. A multi-mesh
//     layer keeps these under the layering threshold T along the cell by construction; off the centreline, and for
//     the single mesh, this term is what limits the region.
// Viewpoints are sampled every `step` metres along the cell (s in [-back, length]), at `laterals` offsets across
// it within the street's half width and at three heights; the envelope is the running maximum along s. Scanning stops
// after the first sample above `stop_rad` (what lies beyond is outside the region).
#pragma once

#include <span>
#include <vector>

#include "farfield/core/bounds.h"
#include "farfield/core/polygon2d.h"
#include "farfield/impostor/validity.h"

namespace farfield::extract {

struct ValidityOptions {
  float step = 1.0f;             // metres between samples along the cell
  float back = 2.0f;             // metres before the cell's start that the region also covers
  float width_share = 0.9f;      // region half width = share x the street's half width (walkers keep within 90%)
  int laterals = 9;              // samples across the street, odd (includes the centreline)
  float below = 0.6f;            // metres below the eye line (a car's 1.2 m eye under a pedestrian's 1.7 m bake)
  float above = 0.3f;            // metres above it
};

// The region of one impostor captured from `p_eye` for a cell ending at `q_eye` on a street `street_width` metres
// wide: `objects` (world bounds) for the per-object term, `triangles` for the per-triangle term, `footprints` of its
// objects for the events between them (none: no pair term). stop_rad > 0: each line's scan stops after the first envelope value above it.
impostor::ValidityRegion computeValidityRegion(const Vec3& p_eye, const Vec3& q_eye, float street_width,
                                               std::span<const Box3> objects,
                                               std::span<const impostor::TriangleError> triangles,
                                               std::span<const Polygon2> footprints,
                                               double stop_rad, const ValidityOptions& options = {});

}  // namespace farfield::extract
