#include "farfield/extract/validity_region.h"

#include <algorithm>
#include <cmath>

#include "farfield/core/error.h"
#include "farfield/urban/visibility_events.h"

namespace farfield::extract {

impostor::ValidityRegion computeValidityRegion(const Vec3& p_eye, const Vec3& q_eye, float street_width,
                                               std::span<const Box3> objects,
                                               std::span<const impostor::TriangleError> triangles,
                                               std::span<const Polygon2> footprints,
                                               double stop_rad, const ValidityOptions& options) {
  if (!(options.step > 0.0f) || !(options.back >= 0.0f) || options.laterals < 1 || options.laterals % 2 == 0 ||
      !(options.below >= 0.0f) || !(options.above >= 0.0f) || !(options.width_share >= 0.0f))
    throw Error("validity options", "step > 0, back >= 0, an odd number of laterals, below, above and width share >= 0");
  if (!(stop_rad > 0.0)) throw Error("validity", "stop angle must be > 0");
  impostor::ValidityRegion region;
  region.origin = p_eye;
  region.end = q_eye;
  region.half_width = 0.5f * street_width * options.width_share;
  region.below = options.below;
  region.above = options.above;
  region.back = options.back;
  region.step = options.step;

  const DVec2 axis_full(double(q_eye.x) - p_eye.x, double(q_eye.y) - p_eye.y);
  const double length = glm::length(axis_full);
  const DVec2 axis = length > 0.0 ? axis_full / length : DVec2(1.0, 0.0);
  const DVec2 across(-axis.y, axis.x);
  const double slope = length > 0.0 ? (double(q_eye.z) - p_eye.z) / length : 0.0;

  std::vector<urban::EventObject> events(footprints.size());
  for (size_t i = 0; i < footprints.size(); ++i) {
    if (footprints[i].empty()) throw Error("validity", "object " + std::to_string(i) + " has an empty footprint");
    events[i].footprint = footprints[i];
  }
  const bool pairs = events.size() >= 2;

  // The error at one viewpoint on the ground, the largest over the heights.
  auto error_at = [&](double s, double l) {
    const DVec2 ground = DVec2(p_eye.x, p_eye.y) + s * axis + l * across;
    double worst = 0.0;
    for (double dz : {-double(options.below), 0.0, double(options.above)}) {
      const Vec3 v(float(ground.x), float(ground.y), float(double(p_eye.z) + slope * s + dz));
      for (const Box3& box : objects) {
        worst = std::max(worst, impostor::parallaxBound(p_eye, v, box));
        if (worst > stop_rad) return worst;
      }
      for (const impostor::TriangleError& triangle : triangles) {
        worst = std::max(worst, impostor::triangleErrorBound(p_eye, v, triangle));
        if (worst > stop_rad) return worst;
      }
    }
    if (pairs) {
      const urban::CellSegment segment{Vec2(p_eye.x, p_eye.y), Vec2(float(ground.x), float(ground.y))};
      worst = std::max(worst, urban::computeEventGraph(events, segment).maxWeight());
    }
    return worst;
  };

  region.laterals = options.laterals;
  const size_t samples = size_t(std::ceil(length / double(options.step))) + 1;
  std::vector<std::vector<float>> rows(size_t(options.laterals));
  size_t longest = 0;
  for (int li = 0; li < options.laterals; ++li) {
    const double l = options.laterals == 1
                         ? 0.0
                         : double(region.half_width) * (2.0 * li / double(options.laterals - 1) - 1.0);
    double envelope = error_at(-double(options.back), l);
    for (size_t k = 0; k < samples && envelope <= stop_rad; ++k) {
      envelope = std::max(envelope, error_at(double(k) * double(options.step), l));
      rows[size_t(li)].push_back(float(std::min(envelope, kPi)));
    }
    longest = std::max(longest, rows[size_t(li)].size());
  }
  // Rows end where their scan stopped; beyond, nothing is valid (pi).
  for (const std::vector<float>& row : rows) {
    region.envelope.insert(region.envelope.end(), row.begin(), row.end());
    region.envelope.insert(region.envelope.end(), longest - row.size(), float(kPi));
  }
  return region;
}

}  // namespace farfield::extract
