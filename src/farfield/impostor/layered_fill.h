// The fill of a layered impostor (impostor/layered.h; Jeschke et al. 2005, section 3.2: an impostor's rendering time
// is estimated by its screen area): alpha-tested quads are shaded over their whole drawn area (its tiles), transparent
// texels included, so what a layered impostor adds to a frame is, beyond a few draw calls, the pixels its tiles cover,
// layer over layer.
#pragma once

#include "farfield/core/error_bound.h"
#include "farfield/impostor/layered.h"

namespace farfield::impostor {

// An estimate of the frame pixels the plan's quads cover, summed over the layers, seen from any viewpoint of its shaft
// at least `distance` metres from the apex (>= the shaft's minimum distance; smaller values are raised to it), in
// frames of `frame`'s focal length: each quad's area over the square of a lower bound of its distance from such a
// viewpoint (max(distance - radius, distance cos(apex_angle / 2) - depth), the bounds planLayered uses for texels),
// capped at the frame's pixels, times the part of the quad that is drawn (LayerPlan::cover: planned or measured).
// Falls as 1 / distance^2: a CPV far out in the shaft pays less fill than its nearest viewpoint. Pure arithmetic. The
// quads as planned (cropped ones are smaller: the estimate is then theirs).
double layeredFillPixels(const LayeredPlan& plan, double distance, const ErrorBound& frame);

}  // namespace farfield::impostor
