// Parallax (visibility) error of an impostor measured from object-id renders (Decoret et al. 1999, sections 3-4:
// the displacement, in pixels, between where an object is drawn and where it should be seen).
//
// Inputs are two item buffers of the same size (image::IdImage, 0 = background): the reference, full geometry, and
// the test, the impostor drawn with per-object ids (impostor::GpuImpostorOptions::split_by_object_id). Two ids
// differ at a *mismatching* pixel. Its displacement is the larger of
//   - test side: the test shows object k (not background, not ignored) -> the Euclidean distance, between pixel
//     centres, to the nearest reference pixel showing k (the object drawn there belongs that far away);
//   - reference side: the reference shows object k (not background, not ignored) -> the distance to the nearest test
//     pixel showing k (a de-occluded or missing part of k, the "rubber sheet" hole).
// When k is absent from the other image the distance is the image diagonal, sqrt(width^2 + height^2) (larger than
// any distance inside the image). A pixel whose two ids are both background or ignored (say the ground, drawn as
// geometry in both, against the sky) does not count, nor a pixel where the ids agree.
//
// The distances are exact: one Felzenszwalb-Huttenlocher squared Euclidean distance transform per id that occurs
// at a mismatching pixel, evaluated only on the rows that hold such pixels.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "farfield/image/image.h"

namespace farfield::eval {

struct ParallaxOptions {
  std::vector<uint32_t> ignore_ids;  // treated as background on both sides (0 is always background)
  // Percentile of the mismatching pixels' displacements, in (0, 1]; linear interpolation between closest ranks
  // (eval::percentile's rule, frame_stats.h).
  double percentile = 0.99;
  // An object absent from the other image altogether gives no distance on that side instead of the diagonal; a
  // pixel left with no side measured does not count (ParallaxError::absent). For impostors whose triangles carry one
  // object id each (a coarse grid): a small object that is no triangle's majority never appears in their item
  // buffer, and its pixels say nothing about displacement (the crack and PSNR measures see it).
  bool skip_absent = false;
};

struct ParallaxError {
  size_t mismatched = 0;      // mismatching pixels (see above), those left out by skip_absent excluded
  size_t absent = 0;          // pixels left out by skip_absent
  double share = 0.0;         // mismatched / all pixels
  double mean_px = 0.0;       // mean displacement over the mismatching pixels (0 when none)
  double percentile_px = 0.0; // ParallaxOptions::percentile of the displacements (0 when none)
  double max_px = 0.0;        // largest displacement (0 when none)
  // The percentile over every object pixel (where either image shows a counted object; agreeing pixels count as 0
  // displacement): "this share of what is drawn lies within this many pixels of its place". Robust when few pixels
  // mismatch, where percentile_px is the tail of the mismatching pixels alone. 0 without object pixels.
  size_t object_pixels = 0;
  double object_percentile_px = 0.0;
  int worst_x = -1, worst_y = -1;  // a pixel with the largest displacement (first in row order), -1 when none
};

// Throws farfield::Error when the sizes differ or the percentile is outside (0, 1]. Empty images give zeros.
ParallaxError parallaxError(const image::IdImage& reference, const image::IdImage& test,
                            const ParallaxOptions& options = {});

// Per-pixel displacement map of the same computation (0 where a pixel does not count), for inspection and tests.
image::Image<float> parallaxErrorMap(const image::IdImage& reference, const image::IdImage& test,
                                     const ParallaxOptions& options = {});

// A frame's parallax as bench and the viewer report it: object_percentile_px with skip_absent (impostor triangles
// carry their majority object's id, so small objects may be absent); NaN when the frame shows ids above
// object_count (ids that are not scene objects: the parallax cannot be measured).
double frameParallaxPx(const image::IdImage& reference, const image::IdImage& frame, size_t object_count);

// The same per pixel as a picture: black where the object is right, dark red to yellow for 1 to 32+ pixels.
image::ColorImage parallaxHeatmap(const image::IdImage& reference, const image::IdImage& frame);

}  // namespace farfield::eval
