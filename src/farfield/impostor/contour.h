// External contour(s) of the data in a captured impostor image (Sillion et al. 1997, section 4.2, step 3).
//
// Data and background: a pixel is impostor data when its window depth is above 0 (reversed Z: 0 is the far plane
// and the cleared background, i.e. sky) and its colour is not kSeenFromBelowColor, the colour the capture gives to
// pixels where the first surface seen is the back face of a single-sided surface (the bottom of a ground element
// seen from below, see capture.h). Everything else is background.
//
// Image coordinates: x right, y down, in pixels; pixel (i, j) covers [i, i+1] x [j, j+1], its centre is
// (i + 0.5, j + 0.5) (Camera::unproject's convention). Contours run along pixel edges, so their vertices are pixel
// corners (integer coordinates).
#pragma once

#include <cstdint>
#include <vector>

#include "farfield/core/math.h"
#include "farfield/image/image.h"

namespace farfield::impostor {

// Reserved colour of "seen from below" pixels. Its alpha of 0 cannot come out of the renderer for a drawn surface
// (texels with alpha below 0.5 are cut out) nor from the clear colour (alpha 1), so it never collides with data.
inline constexpr image::Rgba8 kSeenFromBelowColor{255, 0, 255, 0};

inline bool isImpostorData(const image::Rgba8& color, float window_depth) {
  return window_depth > 0.0f && color != kSeenFromBelowColor;
}

// 1 for data pixels, 0 for background. Throws farfield::Error when the images differ in size.
image::Image<uint8_t> dataMask(const image::ColorImage& color, const image::DepthImage& depth);

// Boundaries of the data in `mask` (non-zero = data) as closed polygons through pixel corners, without repeated
// closing vertex and without collinear vertices. Data pixels are 4-connected: two data pixels touching only at a
// corner belong to different loops (which then share that corner). Orientation: the shoelace area in image
// coordinates is positive for the outer boundary of a region and negative for a hole, and the sum of the signed
// areas of all loops equals the number of data pixels.
std::vector<std::vector<DVec2>> traceBoundaries(const image::Image<uint8_t>& mask);

struct ContourOptions {
  double tolerance_px = 1.0;  // Douglas-Peucker tolerance (pixels)
  double min_area_px = 0.0;   // loops (regions or holes) with |area| below this are dropped (counted)
};

struct ContourLoop {
  std::vector<DVec2> points;  // simplified; a subset of the traced pixel corners
  double traced_area = 0.0;   // signed area of the traced loop before simplification (pixels)
  size_t traced_vertices = 0;
  bool hole() const { return traced_area < 0.0; }
};

struct Contours {
  std::vector<ContourLoop> loops;
  size_t dropped_loops = 0;     // below min_area_px
  double dropped_area = 0.0;    // sum of |area| of the dropped loops
  size_t traced_vertices = 0;   // before simplification, all loops
  size_t vertexCount() const;   // after simplification (= number of contour segments)
};

// Traces the boundaries of the mask and simplifies each loop with Douglas-Peucker (loops that collapse below
// 3 vertices are dropped and counted).
Contours extractContours(const image::Image<uint8_t>& mask, const ContourOptions& options = {});

// Shoelace area in image coordinates (positive for the orientation of outer loops above).
double signedArea(const std::vector<DVec2>& polygon);

}  // namespace farfield::impostor
