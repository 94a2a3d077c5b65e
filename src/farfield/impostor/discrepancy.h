// Depth discrepancy lines of a captured impostor image (Sillion et al. 1997, section 4.2, step 4): the lines along
// which the depth jumps, which the triangulation must follow so that the impostor keeps its parallax.
#pragma once

#include <cstdint>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/core/math.h"
#include "farfield/image/image.h"

namespace farfield::impostor {

// How the depth difference of two neighbouring pixels at linear depths a and b (metres) is measured.
enum class DiscrepancyMetric {
  Relative,  // |a - b| / min(a, b): scale-free, the same threshold works for a step at 50 m and at 2 km (default)
  Absolute,  // |a - b| in metres
};

struct DiscrepancyOptions {
  DiscrepancyMetric metric = DiscrepancyMetric::Relative;
  // Pairs of neighbours at or above the threshold are a depth discontinuity; below it they lie on one surface.
  // Relative default 0.1: a 10 m gap at 100 m.
  float threshold = 0.1f;
  double tolerance_px = 1.0;     // Douglas-Peucker tolerance of the chain polylines (pixels)
  size_t min_chain_pixels = 3;   // shorter chains are consumed but give no polyline (counted)
};

// Linear depth in metres (Camera::linearDepth) of the pixels where mask != 0; 0 elsewhere. Throws farfield::Error
// when the sizes differ from each other or from the camera's, or when a data pixel's depth is not in (0, 1].
image::DepthImage linearizeDepth(const image::DepthImage& window_depth, const image::Image<uint8_t>& mask,
                                 const Camera& camera);

// Discrepancy of a pair of linear depths under the metric.
float pairDiscrepancy(float a, float b, DiscrepancyMetric metric);
inline bool depthContinuous(float a, float b, const DiscrepancyOptions& options) {
  return pairDiscrepancy(a, b, options.metric) < options.threshold;
}

// Depth discrepancy image: at each data pixel, the largest pair discrepancy to its data 8-neighbours (background
// neighbours do not count: that boundary is the contour's); 0 at background pixels.
image::Image<float> discrepancyImage(const image::DepthImage& linear_depth, const image::Image<uint8_t>& mask,
                                     DiscrepancyMetric metric);

struct DiscrepancyChain {
  std::vector<IVec2> pixels;      // in order along the chain
  std::vector<DVec2> polyline;    // simplified, through pixel centres (x + 0.5, y + 0.5); empty for short chains
};

struct DiscrepancyLines {
  image::Image<float> discrepancy;       // discrepancyImage()
  std::vector<DiscrepancyChain> chains;  // every chain followed, short ones included (empty polyline)
  size_t pixels_above = 0;               // data pixels with discrepancy >= threshold
  size_t short_chains = 0;               // chains below min_chain_pixels (no polyline)
  size_t segmentCount() const;           // constraint segments of all polylines
};

// The paper's loop, until no pixel above the threshold is left unused:
//   1. take the unused pixel with the largest discrepancy;
//   2. follow the chain of unused pixels at or above the threshold that lie on the same surface (depth continuous
//      with the current pixel), in both directions, until no such neighbour is left or the chain reaches a pixel
//      of the external contour (a data pixel with a background 4-neighbour or on the image border);
//   3. approximate the chain by a polyline (Douglas-Peucker).
// A depth step thus gives two parallel chains, one on each side, so the near and the far surface each get an
// edge of their own and the triangles that span the step are one pixel wide.
DiscrepancyLines extractDiscrepancyLines(const image::DepthImage& linear_depth, const image::Image<uint8_t>& mask,
                                         const DiscrepancyOptions& options = {});

}  // namespace farfield::impostor
