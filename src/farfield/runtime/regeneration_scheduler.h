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
};

struct RegenerationSchedule {
  std::vector<uint32_t> regenerate;  // nodes, most invalid first
  std::vector<uint32_t> geometry;    // nodes drawn as geometry this frame
  double predicted_ms = 0.0;         // base + what the choices cost
};

// Starts from every request drawn as geometry (base_ms + the geometry), then takes the requests in decreasing
// error_ratio (ties: lower node first) and regenerates each whose change of cost (regenerate + image - geometry)
// keeps the prediction at or under t_max_ms, at most max_regenerations of them. A request that does not fit is
// skipped, and later (less invalid, cheaper) ones may still fit. t_max_ms <= 0: no budget (every request up to
// the count is regenerated).
RegenerationSchedule scheduleRegenerations(std::span<const RegenerationRequest> requests, double base_ms,
                                           double t_max_ms, int max_regenerations);

}  // namespace farfield::runtime
