// Popping: how much a mode's image jumps from one frame to the next beyond what the scene itself does. A
// representation switch (geometry to impostor, one impostor to the next, a dynamic impostor refreshed late) changes
// many pixels in one frame while the full-geometry reference changes smoothly; the per-frame error against the
// reference (PSNR, parallax) does not show that, since a small error that appears at once looks like a small error.
//
// Definition, per pair of consecutive measured frames (k-1, k), over RGB in 8-bit units (0..255):
//   popping(k) = max(0, MAE(mode_k, mode_{k-1}) - MAE(reference_k, reference_{k-1}))
// where MAE is image::meanAbsoluteError: the mode's image change minus the reference's image change between the same
// two camera positions, clamped at 0. Why this shape:
//   - identical mode and reference sequences give exactly 0, and so does any mode whose frames change by as much as
//     the reference's (a constant error, e.g. a fixed colour shift, or a displacement that moves with the camera:
//     its edges travel as far as the reference's);
//   - a mode that freezes (a stale impostor) changes less than the reference: that is an image error (PSNR, parallax),
//     not a pop, and gives 0 here; the jump when it is finally refreshed gives the peak;
//   - the difference of means (not a per-pixel difference of changes) does not count the displacement error of every
//     moving edge on every frame, which would bury the pops under parallax that the parallax error already reports.
// A pop that coincides with a large change of the reference (a fast turn) is partly masked; over a camera path the
// peaks still stand out, and the report gives mean, p99 and max.
#pragma once

#include <span>
#include <vector>

#include "farfield/image/image.h"

namespace farfield::eval {

// popping(k) above for one pair of frames. All four images must have the same size (farfield::Error otherwise).
double poppingError(const image::ColorImage& mode_previous, const image::ColorImage& mode_current,
                    const image::ColorImage& reference_previous, const image::ColorImage& reference_current);

// popping(k) for every frame of two sequences of the same length: NaN for frame 0 (no previous frame). Throws
// farfield::Error when the lengths or sizes differ.
std::vector<double> poppingSeries(std::span<const image::ColorImage> mode,
                                  std::span<const image::ColorImage> reference);

}  // namespace farfield::eval
