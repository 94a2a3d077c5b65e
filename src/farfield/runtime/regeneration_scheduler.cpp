// Greedy scheduling of impostor regenerations under the frame budget, most invalid first
// (steed-ibr-impostors-lecture, part 2, "Impostors"; Decoret et al. 1999, section 5.5, "how much time we have to
// accomplish such updates").
#include "farfield/runtime/regeneration_scheduler.h"

#include <algorithm>
#include <numeric>

namespace farfield::runtime {

RegenerationSchedule scheduleRegenerations(std::span<const RegenerationRequest> requests, double base_ms,
                                           double t_max_ms, int max_regenerations, double invest_ms,
                                           bool pay_back) {
  RegenerationSchedule s;
  s.predicted_ms = base_ms;
  for (const RegenerationRequest& r : requests) s.predicted_ms += r.geometry_ms;
  s.lost = t_max_ms > 0.0 && s.predicted_ms > t_max_ms;
  // A lost frame's limit: what it costs anyway plus the investment (none without one).
  const double limit = s.lost ? s.predicted_ms + std::max(invest_ms, 0.0) : t_max_ms;
  std::vector<size_t> order(requests.size());
  std::iota(order.begin(), order.end(), size_t(0));
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    if (requests[a].error_ratio != requests[b].error_ratio) return requests[a].error_ratio > requests[b].error_ratio;
    return requests[a].node < requests[b].node;
  });
  std::vector<bool> chosen(requests.size(), false);
  int count = 0;
  for (const size_t i : order) {
    if (count >= max_regenerations) break;
    const RegenerationRequest& r = requests[i];
    const double delta = r.regenerate_ms + r.image_ms - r.geometry_ms;
    const bool pays = delta <= r.expected_reuse * (r.geometry_ms - r.image_ms);
    if (s.lost && (invest_ms <= 0.0 || !pays)) continue;
    if (pay_back && !pays) continue;
    if (t_max_ms > 0.0 && s.predicted_ms + delta > limit) continue;
    s.predicted_ms += delta;
    chosen[i] = true;
    s.regenerate.push_back(r.node);
    ++count;
  }
  for (const size_t i : order)
    if (!chosen[i]) s.geometry.push_back(requests[i].node);
  return s;
}

}  // namespace farfield::runtime
