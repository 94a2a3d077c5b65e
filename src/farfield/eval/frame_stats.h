// Frame statistics: median, percentiles, maximum and mean of per-frame times (or any per-frame number).
//
// Percentiles use linear interpolation between closest ranks (the "linear" / type-7 definition, numpy's default):
// for n sorted values v[0..n-1] and p in [0, 100], the rank is r = p / 100 * (n - 1) and the percentile is
// v[floor(r)] + (r - floor(r)) * (v[floor(r) + 1] - v[floor(r)]). So p0 is the minimum, p100 the maximum and p50
// the usual median (the mean of the two middle values for even n).
#pragma once

#include <cstddef>
#include <span>

namespace farfield::eval {

struct FrameSummary {
  size_t count = 0;
  double median = 0.0;
  double p95 = 0.0;
  double p99 = 0.0;
  double min = 0.0;
  double max = 0.0;
  double mean = 0.0;
};

// Percentile p (0..100) of the values as documented above. Empty input gives 0; p is clamped to [0, 100];
// non-finite values are the caller's business (they sort as std::sort with operator< leaves them).
double percentile(std::span<const double> values, double p);

// All of FrameSummary at once (one sort). Empty input gives all zeros.
FrameSummary summarize(std::span<const double> values);

}  // namespace farfield::eval
