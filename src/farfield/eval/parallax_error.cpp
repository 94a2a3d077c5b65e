// Parallax error from item buffers (Decoret et al. 1999, sections 3-4); the distance transform is Felzenszwalb and
// Huttenlocher's (2012) separable lower envelope of parabolas.
#include "farfield/eval/parallax_error.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <unordered_map>

#include "farfield/core/error.h"
#include "farfield/eval/frame_stats.h"

namespace farfield::eval {
namespace {

constexpr int64_t kInf = std::numeric_limits<int64_t>::max() / 4;

// The id a pixel counts as: ignored ids are background.
std::vector<uint32_t> effectiveIds(const image::IdImage& image, const std::vector<uint32_t>& ignore_sorted) {
  std::vector<uint32_t> out(image.pixels());
  if (ignore_sorted.empty()) return out;
  // Item buffers hold long runs of one id: remember the last answer instead of searching every pixel.
  uint32_t last_id = 0, last_out = 0;
  for (uint32_t& id : out) {
    if (id != last_id) {
      last_id = id;
      last_out = std::binary_search(ignore_sorted.begin(), ignore_sorted.end(), id) ? 0u : id;
    }
    id = id == 0 ? 0u : last_out;
  }
  return out;
}

// Lower envelope of the parabolas (x - q)^2 + f[q] over the sites with finite f, evaluated at every x in [0, n):
// the 1D squared distance transform. Exact in integers: the breakpoints are rationals with denominators <= 2n, so the
// double comparisons only disagree with exact arithmetic at exact ties, where every choice gives the same minimum.
// Returns false (d untouched) when no site is finite.
bool lowerEnvelope(const std::vector<int64_t>& f, std::vector<int64_t>& d, std::vector<int>& v,
                   std::vector<double>& z) {
  const int n = int(f.size());
  v.resize(size_t(n));
  z.resize(size_t(n) + 1);
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (f[size_t(q)] >= kInf) continue;
    if (k < 0) {
      k = 0;
      v[0] = q;
      z[0] = -std::numeric_limits<double>::infinity();
      z[1] = std::numeric_limits<double>::infinity();
      continue;
    }
    const double fq = double(f[size_t(q)]) + double(q) * double(q);
    double s = 0.0;
    for (;;) {
      const int p = v[size_t(k)];
      s = (fq - (double(f[size_t(p)]) + double(p) * double(p))) / (2.0 * double(q - p));
      if (s > z[size_t(k)]) break;
      --k;  // z[0] = -inf, so k never drops below 0
    }
    ++k;
    v[size_t(k)] = q;
    z[size_t(k)] = s;
    z[size_t(k) + 1] = std::numeric_limits<double>::infinity();
  }
  if (k < 0) return false;
  k = 0;
  for (int x = 0; x < n; ++x) {
    while (z[size_t(k) + 1] < double(x)) ++k;
    const int64_t dx = int64_t(x - v[size_t(k)]);
    d[size_t(x)] = dx * dx + f[size_t(v[size_t(k)])];
  }
  return true;
}

// Squared distances from the query pixels to the nearest feature pixel (both as row-major pixel indices, ascending).
// The column pass runs only on the rows that hold queries: per column, the feature rows are a sorted list and a
// pointer per column advances with the query row; the row pass is the lower envelope over those column distances.
// Work: O(features + width * query rows).
void squaredDistances(int width, const std::vector<uint32_t>& features, const std::vector<uint32_t>& queries,
                      std::vector<int64_t>& out) {
  out.assign(queries.size(), kInf);
  if (features.empty() || queries.empty()) return;
  const size_t w = size_t(width);
  // Feature rows per column, compressed (row-major input keeps each column's rows ascending).
  std::vector<uint32_t> start(w + 1, 0);
  for (uint32_t p : features) ++start[p % w + 1];
  for (size_t x = 0; x < w; ++x) start[x + 1] += start[x];
  std::vector<int> rows(features.size());
  {
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    for (uint32_t p : features) rows[fill[p % w]++] = int(p / w);
  }
  std::vector<uint32_t> ptr(start.begin(), start.end() - 1);
  std::vector<int64_t> g(w), d(w);
  std::vector<int> v;
  std::vector<double> z;
  size_t i = 0;
  while (i < queries.size()) {
    const int y = int(queries[i] / w);
    for (size_t x = 0; x < w; ++x) {
      uint32_t& p = ptr[x];
      const uint32_t end = start[x + 1];
      while (p < end && rows[p] < y) ++p;  // first feature at or below row y
      int64_t best = kInf;
      if (p < end) best = int64_t(rows[p] - y);
      if (p > start[x]) best = std::min(best, int64_t(y - rows[p - 1]));
      g[x] = best >= kInf ? kInf : best * best;
    }
    lowerEnvelope(g, d, v, z);  // features is not empty, so some column has a finite distance
    for (; i < queries.size() && int(queries[i] / w) == y; ++i) out[i] = d[queries[i] % w];
  }
}

struct Displacements {
  std::vector<uint32_t> pixels;  // mismatching pixels, row-major ascending
  std::vector<double> px;        // their displacements
  size_t absent = 0;             // pixels left out by ParallaxOptions::skip_absent
  size_t object_pixels = 0;      // pixels where either image shows an object (not background, not ignored)
};

Displacements computeDisplacements(const image::IdImage& reference, const image::IdImage& test,
                                   const ParallaxOptions& options) {
  if (reference.width() != test.width() || reference.height() != test.height())
    throw Error("parallaxError",
                "reference is " + std::to_string(reference.width()) + "x" + std::to_string(reference.height()) +
                    " but test is " + std::to_string(test.width()) + "x" + std::to_string(test.height()));
  if (!(options.percentile > 0.0 && options.percentile <= 1.0))
    throw Error("parallaxError", "percentile " + std::to_string(options.percentile) + " is not in (0, 1]");

  std::vector<uint32_t> ignore = options.ignore_ids;
  std::sort(ignore.begin(), ignore.end());
  const std::vector<uint32_t> ref = effectiveIds(reference, ignore);
  const std::vector<uint32_t> tst = effectiveIds(test, ignore);

  Displacements out;
  // Queries per (side, id): side 0 looks for the test's id in the reference, side 1 for the reference's id in the
  // test. Values are indices into out.pixels, ascending (hence row-major).
  std::unordered_map<uint32_t, std::vector<uint32_t>> queries[2];
  for (size_t p = 0; p < ref.size(); ++p) {
    out.object_pixels += (ref[p] != 0 || tst[p] != 0) ? 1 : 0;
    if (ref[p] == tst[p]) continue;  // agreeing ids, or both background/ignored
    const uint32_t index = uint32_t(out.pixels.size());
    out.pixels.push_back(uint32_t(p));
    if (tst[p] != 0) queries[0][tst[p]].push_back(index);
    if (ref[p] != 0) queries[1][ref[p]].push_back(index);
  }
  const size_t n = out.pixels.size();
  std::vector<int64_t> d2(n, 0);
  std::vector<uint8_t> measured(n, 0), absent(n, 0);
  if (n == 0) return out;

  const int64_t w = reference.width(), h = reference.height();
  const int64_t diagonal2 = w * w + h * h;
  std::vector<uint32_t> query_pixels;
  std::vector<int64_t> dist;
  for (int side = 0; side < 2; ++side) {
    if (queries[side].empty()) continue;
    // Feature pixels of the queried ids, in the image searched, row-major.
    const std::vector<uint32_t>& searched = side == 0 ? ref : tst;
    std::unordered_map<uint32_t, std::vector<uint32_t>> features;
    for (const auto& [id, list] : queries[side]) features[id];
    uint32_t last_id = 0;
    std::vector<uint32_t>* last_list = nullptr;
    for (size_t p = 0; p < searched.size(); ++p) {
      const uint32_t id = searched[p];
      if (id == 0) continue;
      if (id != last_id) {  // runs of one id: one look-up per run
        last_id = id;
        const auto it = features.find(id);
        last_list = it == features.end() ? nullptr : &it->second;
      }
      if (last_list) last_list->push_back(uint32_t(p));
    }
    for (const auto& [id, list] : queries[side]) {
      const std::vector<uint32_t>& f = features[id];
      if (f.empty()) {  // the object is not in the other image at all
        for (uint32_t q : list) {
          if (options.skip_absent)
            absent[q] = 1;
          else
            d2[q] = std::max(d2[q], diagonal2);
        }
        continue;
      }
      query_pixels.resize(list.size());
      for (size_t k = 0; k < list.size(); ++k) query_pixels[k] = out.pixels[list[k]];
      squaredDistances(reference.width(), f, query_pixels, dist);
      for (size_t k = 0; k < list.size(); ++k) {
        d2[list[k]] = std::max(d2[list[k]], dist[k]);
        measured[list[k]] = 1;
      }
    }
  }
  // With skip_absent, a pixel none of whose sides could be measured leaves the statistics (counted as absent).
  size_t kept = 0;
  out.px.resize(n);
  for (size_t k = 0; k < n; ++k) {
    if (options.skip_absent && absent[k] && !measured[k]) {
      ++out.absent;
      continue;
    }
    out.pixels[kept] = out.pixels[k];
    out.px[kept++] = std::sqrt(double(d2[k]));
  }
  out.pixels.resize(kept);
  out.px.resize(kept);
  return out;
}

}  // namespace

ParallaxError parallaxError(const image::IdImage& reference, const image::IdImage& test,
                            const ParallaxOptions& options) {
  const Displacements d = computeDisplacements(reference, test, options);
  ParallaxError e;
  e.mismatched = d.pixels.size();
  e.absent = d.absent;
  if (e.mismatched == 0) return e;
  e.share = double(e.mismatched) / double(reference.pixelCount());
  double sum = 0.0;
  size_t worst = 0;
  for (size_t k = 0; k < d.px.size(); ++k) {
    sum += d.px[k];
    if (d.px[k] > d.px[worst]) worst = k;
  }
  e.mean_px = sum / double(e.mismatched);
  e.max_px = d.px[worst];
  e.worst_x = int(d.pixels[worst] % uint32_t(reference.width()));
  e.worst_y = int(d.pixels[worst] / uint32_t(reference.width()));
  e.percentile_px = percentile(d.px, options.percentile * 100.0);
  // Over the object pixels, the agreeing ones at 0: the same rank rule on the zeros followed by the sorted
  // displacements (pixels left out as absent are not object pixels of either measure).
  const size_t objects = d.object_pixels - d.absent;
  e.object_pixels = objects;
  if (objects > 0) {
    std::vector<double> all(objects - e.mismatched, 0.0);
    all.insert(all.end(), d.px.begin(), d.px.end());
    e.object_percentile_px = percentile(all, options.percentile * 100.0);
  }
  return e;
}

image::Image<float> parallaxErrorMap(const image::IdImage& reference, const image::IdImage& test,
                                     const ParallaxOptions& options) {
  const Displacements d = computeDisplacements(reference, test, options);
  image::Image<float> map(reference.width(), reference.height(), 0.0f);
  for (size_t k = 0; k < d.pixels.size(); ++k) map.data()[d.pixels[k]] = float(d.px[k]);
  return map;
}

double frameParallaxPx(const image::IdImage& reference, const image::IdImage& frame, size_t object_count) {
  for (uint32_t id : frame.pixels())
    if (id > object_count) return std::numeric_limits<double>::quiet_NaN();
  ParallaxOptions options;
  options.skip_absent = true;
  return parallaxError(reference, frame, options).object_percentile_px;
}

image::ColorImage parallaxHeatmap(const image::IdImage& reference, const image::IdImage& frame) {
  ParallaxOptions options;
  options.skip_absent = true;
  const image::Image<float> map = parallaxErrorMap(reference, frame, options);
  image::ColorImage out(map.width(), map.height(), image::Rgba8(0, 0, 0, 255));
  for (size_t i = 0; i < map.pixelCount(); ++i) {
    const float px = map.pixels()[i];
    if (!(px > 0.0f)) continue;
    const float t = std::min(1.0f, px / 32.0f);
    out.pixels()[i] = image::Rgba8(uint8_t(96 + 159 * t), uint8_t(255 * t * t), 0, 255);
  }
  return out;
}

}  // namespace farfield::eval
