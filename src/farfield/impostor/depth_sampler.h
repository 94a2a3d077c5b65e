// Window depth of the captured image at any image point, for reprojecting impostor mesh vertices to 3D (Sillion et
// al. 1997, section 4.2, step 6), shared by the depth-mesh and the grid-mesh impostors.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "farfield/core/math.h"
#include "farfield/image/image.h"
#include "farfield/impostor/discrepancy.h"

namespace farfield::impostor {

// The rule, for an image point p (pixel corners at integer coordinates):
//   1. Source pixel: among the data pixels whose closed square contains p (one inside a pixel, two on an edge,
//      up to four at a corner), the nearest one (largest window depth). When none is data (a point off the data,
//      e.g. a grid-mesh vertex in the sky), the data pixel nearest to p's pixel, if it is within max_search_px
//      (8-connected distance).
//   2. Window depth at p extrapolated from the source pixel's centre with its depth gradient, estimated from the
//      neighbours that lie on the same surface (depth continuous under the discrepancy options): central
//      difference when both neighbours along an axis are continuous, one-sided when one is, zero when none.
//      Reversed-Z window depth is an affine function of the image position over a plane, so a vertex on the edge
//      or corner of a planar face lands exactly on that face's plane.
// So a vertex never takes the background depth, and on a depth step it takes the depth of the nearer surface:
// the occluder keeps its silhouette in 3D and the triangles across the step hang behind it, towards the far
// surface, rather than pulling the near edge back.
class DepthSampler {
 public:
  // All images the same size; linear_depth from linearizeDepth(). Keeps references: the images must outlive it.
  DepthSampler(const image::DepthImage& window_depth, const image::Image<uint8_t>& mask,
               const image::DepthImage& linear_depth, const DiscrepancyOptions& continuity);

  struct Sample {
    float window_depth = 0.0f;
    IVec2 pixel{0, 0};  // source pixel
  };
  // nullopt when no data pixel is close enough (max_search_px < 0: no limit).
  std::optional<Sample> sample(const DVec2& p, int max_search_px = 2) const;
  // The source pixel alone (rule 1).
  std::optional<IVec2> sourcePixel(const DVec2& p, int max_search_px = 2) const;

 private:
  void buildNearestMap() const;

  const image::DepthImage& window_;
  const image::Image<uint8_t>& mask_;
  const image::DepthImage& linear_;
  DiscrepancyOptions continuity_;
  // For each pixel, the index of a nearest data pixel and the 8-connected distance to it (built on first use).
  mutable std::vector<int32_t> nearest_;
  mutable std::vector<int32_t> nearest_distance_;
};

}  // namespace farfield::impostor
