#include "farfield/eval/temporal_error.h"

#include <algorithm>
#include <limits>
#include <string>

#include "farfield/core/error.h"
#include "farfield/image/metrics.h"

namespace farfield::eval {

double poppingError(const image::ColorImage& mode_previous, const image::ColorImage& mode_current,
                    const image::ColorImage& reference_previous, const image::ColorImage& reference_current) {
  const auto same = [&](const image::ColorImage& a) {
    return a.width() == mode_current.width() && a.height() == mode_current.height();
  };
  if (!same(mode_previous) || !same(reference_previous) || !same(reference_current))
    throw Error("popping error", "the mode's and the reference's frames must all have the same size");
  const double mode_change = image::meanAbsoluteError(mode_current, mode_previous);
  const double reference_change = image::meanAbsoluteError(reference_current, reference_previous);
  return std::max(0.0, mode_change - reference_change);
}

std::vector<double> poppingSeries(std::span<const image::ColorImage> mode,
                                  std::span<const image::ColorImage> reference) {
  if (mode.size() != reference.size())
    throw Error("popping error", "the mode has " + std::to_string(mode.size()) + " frames, the reference " +
                                     std::to_string(reference.size()));
  std::vector<double> out;
  out.reserve(mode.size());
  for (size_t k = 0; k < mode.size(); ++k)
    out.push_back(k == 0 ? std::numeric_limits<double>::quiet_NaN()
                         : poppingError(mode[k - 1], mode[k], reference[k - 1], reference[k]));
  return out;
}

}  // namespace farfield::eval
