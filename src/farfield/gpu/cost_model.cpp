// Frame-time prediction for the dynamic-update budget (Decoret et al. 1999, section 5.5).
//
// Why a linear model in triangles, draw calls and target pixels: these are the three costs a frame of Farfield's
// renderer has (vertex work per triangle, CPU and driver work per draw, clear and fragment work per pixel), and
// they are what the runtime knows before drawing: the cell's near geometry and impostor triangle counts, its draw
// items, the frame size. Coefficients are measured rather than assumed because they differ by orders of magnitude
// between a GPU and llvmpipe, where this project also runs.
#include "farfield/gpu/cost_model.h"

#include <algorithm>
#include <array>
#include <bit>
#include <limits>
#include <cmath>
#include <memory>
#include <numeric>
#include <random>
#include <string>

#include "farfield/core/error.h"
#include "farfield/core/progress.h"
#include "farfield/core/timer.h"

namespace farfield::gpu {
namespace {

constexpr int kTerms = 5;  // base, triangles, draw calls, pixels, fill

// The design row of a sample, in the units of the coefficients.
std::array<double, kTerms> designRow(const CostSample& s) {
  return {1.0, s.triangles * 1e-6, s.draw_calls, s.pixels * 1e-6, s.fill * 1e-6};
}

// Unconstrained least squares restricted to the terms in `mask`, by modified Gram-Schmidt QR on the columns
// normalised to unit length (the terms differ by orders of magnitude: base ~1, draws ~1000). Returns false when the
// chosen columns are linearly dependent on these samples (that subset then cannot be the answer: a subset of it
// reaches the same residual). On success fills the coefficients (0 outside the mask) and the residual sum of squares.
bool leastSquaresOnSubset(const std::vector<std::array<double, kTerms>>& rows, const std::vector<double>& y,
                          unsigned mask, std::array<double, kTerms>& coef, double& ssr) {
  const size_t n = rows.size();
  std::vector<int> cols;
  for (int t = 0; t < kTerms; ++t)
    if (mask & (1u << t)) cols.push_back(t);
  const size_t k = cols.size();
  // Q: n x k (column-major), R: k x k upper triangular; scale[j] = norm of original column j.
  std::vector<double> q(n * k), r(k * k, 0.0), scale(k, 0.0);
  for (size_t j = 0; j < k; ++j) {
    for (size_t i = 0; i < n; ++i) q[j * n + i] = rows[i][size_t(cols[j])];
    double norm = 0.0;
    for (size_t i = 0; i < n; ++i) norm += q[j * n + i] * q[j * n + i];
    norm = std::sqrt(norm);
    if (!(norm > 0.0)) return false;  // an all-zero term: undetermined
    scale[j] = norm;
    for (size_t i = 0; i < n; ++i) q[j * n + i] /= norm;
  }
  for (size_t j = 0; j < k; ++j) {
    for (size_t p = 0; p < j; ++p) {
      double dot = 0.0;
      for (size_t i = 0; i < n; ++i) dot += q[p * n + i] * q[j * n + i];
      r[p * k + j] = dot;
      for (size_t i = 0; i < n; ++i) q[j * n + i] -= dot * q[p * n + i];
    }
    double norm = 0.0;
    for (size_t i = 0; i < n; ++i) norm += q[j * n + i] * q[j * n + i];
    norm = std::sqrt(norm);
    // Unit columns: what is left after removing the others is the sine of the angle to their span.
    if (norm < 1e-9) return false;
    r[j * k + j] = norm;
    for (size_t i = 0; i < n; ++i) q[j * n + i] /= norm;
  }
  std::vector<double> qty(k, 0.0), c(k, 0.0);
  for (size_t j = 0; j < k; ++j)
    for (size_t i = 0; i < n; ++i) qty[j] += q[j * n + i] * y[i];
  for (size_t j = k; j-- > 0;) {
    double v = qty[j];
    for (size_t p = j + 1; p < k; ++p) v -= r[j * k + p] * c[p];
    c[j] = v / r[j * k + j];
  }
  coef.fill(0.0);
  for (size_t j = 0; j < k; ++j) coef[size_t(cols[j])] = c[j] / scale[j];
  ssr = 0.0;
  for (size_t i = 0; i < n; ++i) {
    double pred = 0.0;
    for (int t = 0; t < kTerms; ++t) pred += coef[size_t(t)] * rows[i][size_t(t)];
    ssr += (y[i] - pred) * (y[i] - pred);
  }
  return true;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

}  // namespace

double CostModel::predict(double triangles, double draw_calls, double pixels, double fill) const {
  const double counted = fill_cap_pixels > 0.0 ? std::min(fill, fill_cap_pixels) : fill;
  return base_ms + ms_per_mtriangle * triangles * 1e-6 + ms_per_draw * draw_calls + ms_per_mpixel * pixels * 1e-6 +
         ms_per_mfill * counted * 1e-6;
}

double CostModel::fillCredit(double total, double removed) const {
  removed = std::clamp(removed, 0.0, std::max(total, 0.0));
  if (!(fill_cap_pixels > 0.0)) return removed;
  return std::max(0.0, removed - std::max(0.0, total - fill_cap_pixels));
}

CostModel CostModel::fit(std::span<const CostSample> samples) {
  if (samples.size() < size_t(kTerms))
    throw Error("cost model", "fitting 5 coefficients needs at least 5 samples, got " +
                                  std::to_string(samples.size()));
  std::vector<std::array<double, kTerms>> rows;
  std::vector<double> y;
  for (size_t i = 0; i < samples.size(); ++i) {
    const CostSample& s = samples[i];
    for (double v : {s.triangles, s.draw_calls, s.pixels, s.fill, s.ms})
      if (!std::isfinite(v) || v < 0.0)
        throw Error("cost model", "sample " + std::to_string(i) + ": value " + std::to_string(v) +
                                      " is not a finite non-negative number");
    rows.push_back(designRow(s));
    y.push_back(s.ms);
  }

  // Non-negative least squares on 5 unknowns by enumerating the 32 subsets of active terms: the constrained
  // optimum is the unconstrained least-squares solution on its own support (whose coefficients are then all >= 0),
  // and every feasible subset solution is a feasible point, so the feasible subset solution with the smallest
  // residual is the optimum. Exact, with no iteration to tune. Subsets are visited by increasing size and a larger
  // one must do strictly better, so terms the data cannot tell apart stay at 0.
  std::array<unsigned, 1u << kTerms> order;
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(),
                   [](unsigned a, unsigned b) { return std::popcount(a) < std::popcount(b); });
  double sst = 0.0;
  const double mean = std::accumulate(y.begin(), y.end(), 0.0) / double(y.size());
  for (double v : y) sst += (v - mean) * (v - mean);
  double yy = 0.0;
  for (double v : y) yy += v * v;
  std::array<double, kTerms> best{};
  double best_ssr = yy;  // the empty subset: every coefficient 0
  for (unsigned mask : order) {
    if (mask == 0) continue;
    std::array<double, kTerms> coef{};
    double ssr = 0.0;
    if (!leastSquaresOnSubset(rows, y, mask, coef, ssr)) continue;
    if (std::any_of(coef.begin(), coef.end(), [](double c) { return c < 0.0; })) continue;
    if (ssr < best_ssr * (1.0 - 1e-9) - 1e-18 * yy) {
      best_ssr = ssr;
      best = coef;
    }
  }

  CostModel model;
  model.base_ms = best[0];
  model.ms_per_mtriangle = best[1];
  model.ms_per_draw = best[2];
  model.ms_per_mpixel = best[3];
  model.ms_per_mfill = best[4];
  model.samples = samples.size();
  model.rms_error_ms = std::sqrt(best_ssr / double(samples.size()));
  if (sst > 1e-12 * std::max(yy, 1e-300))
    model.r2 = 1.0 - best_ssr / sst;
  else
    model.r2 = best_ssr <= 1e-12 * std::max(yy, 1e-300) ? 1.0 : 0.0;
  return model;
}

nlohmann::json CostModel::toJson() const {
  return {{"base_ms", base_ms},   {"ms_per_mtriangle", ms_per_mtriangle}, {"ms_per_draw", ms_per_draw},
          {"ms_per_mpixel", ms_per_mpixel}, {"ms_per_mfill", ms_per_mfill},
          {"fill_cap_pixels", fill_cap_pixels}, {"samples", samples}, {"rms_error_ms", rms_error_ms},
          {"r2", r2}};
}

CostModel calibrateCostModel(gpu::Renderer& renderer, const gpu::GpuScene& gpu_scene,
                             const CalibrationOptions& options) {
  const char* where = "cost model calibration";
  if (options.repeats < 1) throw Error(where, "repeats must be at least 1, got " + std::to_string(options.repeats));
  if (options.sizes.empty()) throw Error(where, "no target sizes");
  for (int s : options.sizes)
    if (s < 1 || s > 16384) throw Error(where, "target size " + std::to_string(s) + " is not in 1..16384");
  if (options.max_triangles == 0) throw Error(where, "max_triangles must be positive");

  // Items that draw something (the renderer skips the others, so they would only add noise to the counts).
  std::vector<gpu::DrawItem> items;
  for (const gpu::DrawItem& item : gpu_scene.drawItems())
    if (item.mesh && item.mesh->triangleCount() > 0) items.push_back(item);
  if (items.empty()) throw Error(where, "the scene has no triangles to measure with");

  // The views every workload is timed from (the sample's time is the mean over them). Frame time depends on what
  // the view does with the triangles (clipped away, tiny, or filling the screen several times over), so the default
  // mixes an overview that frames the scene's bounding sphere from above at an angle (every item in view, part of
  // the target covered) with two views from opposite corners low over the scene towards its centre (as from a
  // street: most of the target covered, much overdraw, part of the scene behind the eye).
  Box3 bounds;
  for (const gpu::DrawItem& item : items) bounds.expand(transformBox(item.mesh->bounds(), item.transform));
  std::vector<Camera> views = options.views;
  if (views.empty()) {
    const float radius = std::max(0.5f * glm::length(bounds.extent()), 1e-2f);
    const Vec3 centre = bounds.center();
    Camera overview;
    overview.at = centre;
    overview.eye = centre + glm::normalize(Vec3(-0.55f, -0.75f, 0.65f)) * (2.2f * radius);  // 60 deg fits 2 r
    overview.near_plane = 0.5f * radius;
    overview.far_plane = 4.0f * radius;
    views.push_back(overview);
    const Vec3 e = bounds.extent();
    const float low = bounds.lo.z + 0.1f * e.z + 1e-3f * radius;
    for (const Vec3& corner : {Vec3(bounds.lo.x + 0.05f * e.x, bounds.lo.y + 0.05f * e.y, low),
                               Vec3(bounds.hi.x - 0.05f * e.x, bounds.hi.y - 0.05f * e.y, low)}) {
      Camera street;
      street.eye = corner;
      street.at = Vec3(centre.x, centre.y, low);
      if (glm::length(street.at - street.eye) < 1e-3f * radius) street.at = street.eye + Vec3(radius, 0.0f, 0.0f);
      street.near_plane = std::max(1e-3f * radius, 1e-3f);
      street.far_plane = 4.0f * radius;
      views.push_back(street);
    }
  }
  for (size_t v = 0; v < views.size(); ++v) {
    const std::string what = "cost model calibration view " + std::to_string(v);
    views[v].validate(what.c_str());
  }

  // Items in a fixed pseudo-random order, so that every prefix is spread over the whole scene (a prefix of the
  // scene's own order would be one corner of a city, covering few pixels).
  std::mt19937 rng(12345u);
  std::shuffle(items.begin(), items.end(), rng);
  uint64_t total_triangles = 0;
  for (const gpu::DrawItem& item : items) total_triangles += item.mesh->triangleCount();
  const uint64_t cap = std::min<uint64_t>(total_triangles, options.max_triangles);
  auto prefix = [&](uint64_t triangles) {
    std::vector<gpu::DrawItem> out;
    uint64_t sum = 0;
    for (const gpu::DrawItem& item : items) {
      const uint64_t t = item.mesh->triangleCount();
      if (!out.empty() && sum + t > triangles) continue;  // skip big items, smaller ones later may still fit
      out.push_back(item);
      sum += t;
      if (sum >= triangles) break;
    }
    return out;
  };

  struct Workload {
    std::vector<gpu::DrawItem> items;
    int size = 0;
  };
  std::vector<int> sizes = options.sizes;
  std::sort(sizes.begin(), sizes.end());
  sizes.erase(std::unique(sizes.begin(), sizes.end()), sizes.end());
  const int mid = sizes[sizes.size() / 2];
  std::vector<Workload> plan;
  // Triangles: growing subsets at the middle size.
  const std::vector<gpu::DrawItem> full = prefix(cap);
  for (uint64_t divisor : {8u, 4u, 2u}) plan.push_back({prefix(std::max<uint64_t>(cap / divisor, 1)), mid});
  plan.push_back({full, mid});
  // Draw calls: a small item repeated, so the draw count grows while triangles and pixels stay few. Small in space,
  // not only in triangles: the item with the fewest triangles is often a ground quad that covers the whole view,
  // and repeating it would measure fill rate, not draw calls. So: the item with the smallest world bounds among
  // those with at most the median triangle count.
  std::vector<uint64_t> counts;
  for (const gpu::DrawItem& item : items) counts.push_back(item.mesh->triangleCount());
  std::nth_element(counts.begin(), counts.begin() + long(counts.size() / 2), counts.end());
  const uint64_t median_triangles = counts[counts.size() / 2];
  auto diagonal = [](const gpu::DrawItem& item) {
    return glm::length(transformBox(item.mesh->bounds(), item.transform).extent());
  };
  gpu::DrawItem smallest = items.front();
  float smallest_diagonal = std::numeric_limits<float>::max();
  for (const gpu::DrawItem& item : items)
    if (item.mesh->triangleCount() <= median_triangles && diagonal(item) < smallest_diagonal) {
      smallest = item;
      smallest_diagonal = diagonal(item);
    }
  const size_t base_draws = std::clamp<size_t>(items.size(), 32, 512);
  for (size_t draws : {base_draws, 4 * base_draws}) {
    const size_t limit = std::max<uint64_t>(1, cap / smallest.mesh->triangleCount());
    plan.push_back({std::vector<gpu::DrawItem>(std::min(draws, limit), smallest), mid});
  }
  // Pixels: an empty frame (clear only) at every size, and the largest workload at every other size (its overdraw
  // is the closest to a frame's).
  for (int s : sizes) {
    plan.push_back({{}, s});
    if (s != mid) plan.push_back({full, s});
  }

  // Warm-up, untimed: one frame of the largest workload per view and size, first into throwaway targets, then into
  // the targets that are timed. The first frames pay one-off driver costs (shader variants, first touch of memory),
  // and on llvmpipe the first targets of a process were measured to run a whole calibration about 1.7 times slower
  // than targets made after some rendering had been done (warming them up in place did not help); drawing into
  // throwaway targets first removes that.
  auto warmUp = [&](int size, gpu::RenderTarget& target) {
    for (const Camera& view : views) {
      Camera c = view;
      c.width = c.height = size;
      renderer.render(c, full, target);
    }
  };
  for (int size : sizes) {
    gpu::RenderTarget throwaway(size, size);
    warmUp(size, throwaway);
  }
  std::vector<std::unique_ptr<gpu::RenderTarget>> targets;
  for (int s : sizes) targets.push_back(std::make_unique<gpu::RenderTarget>(s, s));
  auto targetOf = [&](int s) -> gpu::RenderTarget& {
    return *targets[size_t(std::find(sizes.begin(), sizes.end(), s) - sizes.begin())];
  };

  std::unique_ptr<Progress> progress;
  if (options.progress) progress = std::make_unique<Progress>("calibrate", plan.size());
  std::vector<CostSample> samples;
  for (int size : sizes) warmUp(size, targetOf(size));
  for (const Workload& w : plan) {
    gpu::RenderTarget& target = targetOf(w.size);
    gpu::FrameStats stats;
    double ms = 0.0;
    for (const Camera& view : views) {
      Camera c = view;
      c.width = c.height = w.size;
      std::vector<double> times;
      for (int r = 0; r < options.repeats; ++r) {
        Stopwatch clock;
        stats = renderer.render(c, w.items, target);
        times.push_back(clock.milliseconds());
      }
      ms += median(std::move(times)) / double(views.size());
    }
    samples.push_back({double(stats.triangles), double(stats.draw_calls), double(w.size) * double(w.size), ms});
    if (progress) progress->advance();
  }
  if (progress) progress->finish();
  return CostModel::fit(samples);
}

}  // namespace farfield::gpu
