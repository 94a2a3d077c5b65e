// 3D warping using depth (steed-ibr-impostors-lecture, part 2, "3D warping using depth information: a depth value is
// associated to each pixel, 3D warping is possible; holes appear where data is missing, can be attenuated warping
// multiple images"; "Post-render warping (Mark et al.)"): a colour image with its window depth, seen from one camera,
// moved to another camera's pixels, and the holes it leaves filled from a second image.
#pragma once

#include <cstddef>
#include <cstdint>

#include "farfield/core/camera.h"
#include "farfield/image/image.h"

namespace farfield::impostor {

struct DepthView {
  const image::ColorImage* color = nullptr;
  const image::DepthImage* depth = nullptr;  // window depth, reversed Z (0 = background: not warped)
  Camera camera;                             // its width x height is the images' size
};

struct WarpedImage {
  image::ColorImage color;        // alpha 255 where a source pixel landed, 0 elsewhere (holes and background)
  image::DepthImage depth;        // window depth in the target camera, 0 where nothing landed
  image::Image<uint8_t> source;   // 0 nothing, 1 the primary image, 2 the second one
  size_t from_primary = 0;        // target pixels written
  size_t from_second = 0;
};

// Forward warp: every data pixel of `view` (its centre, at its depth) is carried to `target`'s image and written
// where it is nearer than what is already there (a z-buffer: nearer = larger reversed-Z depth). Single-pixel splats:
// a surface magnified by the warp leaves cracks, one reason for the second image. Throws farfield::Error for images
// whose size is not the camera's.
WarpedImage warpDepthImage(const DepthView& view, const Camera& target);

// The same, then the target pixels nothing landed on are filled from `second` warped to the target (Mark's
// multiple-image warping): the primary image wins wherever it has data.
WarpedImage warpWithHoleFilling(const DepthView& primary, const DepthView& second, const Camera& target);

}  // namespace farfield::impostor
