#include "farfield/eval/frame_stats.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace farfield::eval {
namespace {

// Linear interpolation between closest ranks on already sorted values. Interpolating (rather than nearest rank)
// keeps short benchmark runs (tens of frames) from snapping p95/p99 to the maximum for every n < 20 or < 100.
double sortedPercentile(const std::vector<double>& sorted, double p) {
  if (sorted.empty()) return 0.0;
  p = std::clamp(p, 0.0, 100.0);
  const double rank = p / 100.0 * double(sorted.size() - 1);
  const size_t lo = size_t(std::floor(rank));
  const size_t hi = std::min(lo + 1, sorted.size() - 1);
  const double t = rank - double(lo);
  return sorted[lo] + t * (sorted[hi] - sorted[lo]);
}

}  // namespace

double percentile(std::span<const double> values, double p) {
  std::vector<double> sorted(values.begin(), values.end());
  std::sort(sorted.begin(), sorted.end());
  return sortedPercentile(sorted, p);
}

FrameSummary summarize(std::span<const double> values) {
  FrameSummary s;
  if (values.empty()) return s;
  std::vector<double> sorted(values.begin(), values.end());
  std::sort(sorted.begin(), sorted.end());
  s.count = sorted.size();
  s.median = sortedPercentile(sorted, 50.0);
  s.p95 = sortedPercentile(sorted, 95.0);
  s.p99 = sortedPercentile(sorted, 99.0);
  s.min = sorted.front();
  s.max = sorted.back();
  double sum = 0.0;
  for (double v : sorted) sum += v;
  s.mean = sum / double(sorted.size());
  return s;
}

}  // namespace farfield::eval
