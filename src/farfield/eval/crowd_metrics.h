// Image error restricted to a crowd's pixels: the pixels where the reference or the frame shows an agent (object ids
// with kCrowdIdBit set), so that the city around the crowd, identical in every mode, does not dilute the error.
#pragma once

#include <cstdint>

#include "farfield/image/image.h"
#include "farfield/runtime/crowd_runtime.h"

namespace farfield::eval {

inline constexpr uint32_t kCrowdIdBit = runtime::kAgentIdBit;  // agents do not receive the crowd's shadows

struct CrowdPixelError {
  size_t pixels = 0;         // crowd pixels (either image)
  double psnr_db = 99.0;     // over those pixels, RGB; capped at 99 (identical)
  double bad_share = 0.0;    // share of them off by more than `threshold` in some channel
  double mae = 0.0;          // mean absolute RGB difference, 8-bit units
};

CrowdPixelError crowdPixelError(const image::ColorImage& reference, const image::IdImage& reference_ids,
                                const image::ColorImage& frame, const image::IdImage& frame_ids, int threshold = 8);

// The shadows' error: pixels that show no agent in either image (the city and the ground, which receive the agents'
// shadows) and differ by more than `threshold` in some channel. The city is identical in every mode, so these are
// the pixels where a mode's shadows differ from the reference's.
size_t receiverBadPixels(const image::ColorImage& reference, const image::IdImage& reference_ids,
                         const image::ColorImage& frame, const image::IdImage& frame_ids, int threshold = 8);

// Popping on the crowd's pixels (eval/temporal_error.h's definition, masked): the mode's mean absolute change between
// consecutive frames minus the reference's, over the pixels where any of the four frames shows an agent; >= 0.
double crowdPopping(const image::ColorImage& previous, const image::IdImage& previous_ids,
                    const image::ColorImage& frame, const image::IdImage& frame_ids,
                    const image::ColorImage& previous_reference, const image::IdImage& previous_reference_ids,
                    const image::ColorImage& reference, const image::IdImage& reference_ids);

}  // namespace farfield::eval
