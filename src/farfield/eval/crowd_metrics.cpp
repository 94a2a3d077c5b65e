#include "farfield/eval/crowd_metrics.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "farfield/core/check.h"

namespace farfield::eval {

namespace {
bool crowd(const image::IdImage& ids, size_t i) { return (ids.pixels()[i] & kCrowdIdBit) != 0; }
int channelDiff(const image::Rgba8& a, const image::Rgba8& b, int c) { return std::abs(int(a[c]) - int(b[c])); }
}  // namespace

CrowdPixelError crowdPixelError(const image::ColorImage& reference, const image::IdImage& reference_ids,
                                const image::ColorImage& frame, const image::IdImage& frame_ids, int threshold) {
  FF_CHECK(reference.pixelCount() == frame.pixelCount() && reference_ids.pixelCount() == frame.pixelCount() &&
           frame_ids.pixelCount() == frame.pixelCount());
  CrowdPixelError e;
  double sq = 0.0, abs_sum = 0.0;
  size_t bad = 0;
  for (size_t i = 0; i < frame.pixelCount(); ++i) {
    if (!crowd(reference_ids, i) && !crowd(frame_ids, i)) continue;
    ++e.pixels;
    bool off = false;
    for (int c = 0; c < 3; ++c) {
      const int d = channelDiff(reference.pixels()[i], frame.pixels()[i], c);
      sq += double(d) * d;
      abs_sum += d;
      off = off || d > threshold;
    }
    bad += off ? 1 : 0;
  }
  if (e.pixels == 0) return e;
  const double mse = sq / (3.0 * double(e.pixels));
  e.psnr_db = mse > 0.0 ? std::min(99.0, 10.0 * std::log10(255.0 * 255.0 / mse)) : 99.0;
  e.bad_share = double(bad) / double(e.pixels);
  e.mae = abs_sum / (3.0 * double(e.pixels));
  return e;
}

size_t receiverBadPixels(const image::ColorImage& reference, const image::IdImage& reference_ids,
                         const image::ColorImage& frame, const image::IdImage& frame_ids, int threshold) {
  FF_CHECK(reference.pixelCount() == frame.pixelCount() && reference_ids.pixelCount() == frame.pixelCount() &&
           frame_ids.pixelCount() == frame.pixelCount());
  size_t bad = 0;
  for (size_t i = 0; i < frame.pixelCount(); ++i) {
    if (crowd(reference_ids, i) || crowd(frame_ids, i)) continue;
    for (int c = 0; c < 3; ++c)
      if (channelDiff(reference.pixels()[i], frame.pixels()[i], c) > threshold) {
        ++bad;
        break;
      }
  }
  return bad;
}

double crowdPopping(const image::ColorImage& previous, const image::IdImage& previous_ids,
                    const image::ColorImage& frame, const image::IdImage& frame_ids,
                    const image::ColorImage& previous_reference, const image::IdImage& previous_reference_ids,
                    const image::ColorImage& reference, const image::IdImage& reference_ids) {
  size_t n = 0;
  double mode_change = 0.0, reference_change = 0.0;
  for (size_t i = 0; i < frame.pixelCount(); ++i) {
    if (!crowd(previous_ids, i) && !crowd(frame_ids, i) && !crowd(previous_reference_ids, i) &&
        !crowd(reference_ids, i))
      continue;
    ++n;
    for (int c = 0; c < 3; ++c) {
      mode_change += channelDiff(previous.pixels()[i], frame.pixels()[i], c);
      reference_change += channelDiff(previous_reference.pixels()[i], reference.pixels()[i], c);
    }
  }
  if (n == 0) return 0.0;
  return std::max(0.0, (mode_change - reference_change) / (3.0 * double(n)));
}

}  // namespace farfield::eval
