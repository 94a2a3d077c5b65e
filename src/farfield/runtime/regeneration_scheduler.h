// Scheduling impostor regenerations into the frame budget (steed-ibr-impostors-lecture, part 2, "Impostors ...
// regenerated when invalid"; DESIGN.md, "the frame budget"): each invalid image is either regenerated this frame
// (its objects rendered into the image, then the image drawn) or replaced by its geometry; the most invalid are
// regenerated first, as long as the predicted frame stays under t_max.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace farfield::runtime {

struct RegenerationRequest {
  uint32_t node = 0;
  double error_ratio = 0.0;    // metric error / bound (> 1 invalid); +inf for a node without an image
  double regenerate_ms = 0.0;  // predicted: rendering the image
  double image_ms = 0.0;       // predicted: drawing the image
  double geometry_ms = 0.0;    // predicted: drawing the node's geometry instead
  // Frames the new image is expected to be drawn after the one it is made in (the pay-back rule below needs it;
  // runtime/image_cache.h estimates it from the eye's speed).
  double expected_reuse = 1.0;
};

struct RegenerationSchedule {
  std::vector<uint32_t> regenerate;  // nodes, most invalid first
  std::vector<uint32_t> geometry;    // nodes drawn as geometry this frame
  double predicted_ms = 0.0;         // base + what the choices cost
  bool lost = false;                 // the all-geometry prediction was over t_max (see invest_ms)
};

// Starts from every request drawn as geometry (base_ms + the geometry), then takes the requests in decreasing
// error_ratio (ties: lower node first) and regenerates each whose change of cost (regenerate + image - geometry)
// keeps the prediction at or under t_max_ms, at most max_regenerations of them. A request that does not fit is
// skipped, and later (less invalid, cheaper) ones may still fit. t_max_ms <= 0: no budget (every request up to
// the count is regenerated).
//
// A lost frame (the all-geometry prediction is already over t_max_ms: the frame breaks the budget whatever is
// chosen) would otherwise regenerate nothing, and a cache that starts that way never gets its images: every later
// frame draws the same geometry and is lost too. With invest_ms > 0 such a frame still regenerates, in the same
// order, the requests that pay for themselves over their expected reuse (regenerate + image - geometry <=
// expected_reuse x (geometry - image): what the frame pays beyond the geometry, the later frames save), as long as
// the prediction stays within the all-geometry prediction + invest_ms. An image expected to serve no later frame
// (expected_reuse 0) is never an investment. invest_ms = 0: a lost frame draws every request as geometry.
//
// pay_back: every frame, lost or not, takes only the requests that pay for themselves that way; the others are
// drawn as geometry even where the budget would have room for their regeneration (an image that does not live long
// enough costs more than the exact geometry it replaces).
RegenerationSchedule scheduleRegenerations(std::span<const RegenerationRequest> requests, double base_ms,
                                           double t_max_ms, int max_regenerations, double invest_ms = 0.0,
                                           bool pay_back = false);

}  // namespace farfield::runtime
