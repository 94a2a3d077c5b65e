// `farfield calibrate` (eval/calibration.h): random views lie in the view space and repeat with the seed; the safety
// factor taken at the quantile 1 bounds every validation view it was derived from, and a lower quantile leaves the
// share of views above it that the quantile says; bad options are errors.
#include "farfield/eval/calibration.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/core/object_fill.h"
#include "farfield/gen/city.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/renderer.h"
#include "farfield/scene/bvh.h"

namespace farfield::eval {
namespace {

const scene::Scene& smallCity() {
  static const scene::Scene* s = [] {
    gen::CityOptions o;
    o.blocks = 12;
    o.detail = 0;
    o.seed = 8;
    o.objects = gen::ObjectGrouping::Buildings;
    return new scene::Scene(gen::generateCity(o).scene);
  }();
  return *s;
}

// Quick runs: 64 x 64 frames, one render per view, no layered terms unless asked.
CalibrateOptions quickOptions(size_t views, size_t layered_samples = 0) {
  CalibrateOptions o;
  o.width = o.height = 64;
  o.views = views;
  o.fit_views = 12;
  o.repeats = 1;
  o.progress = false;
  o.layered_samples = layered_samples;
  return o;
}

TEST(CalibrationTest, RandomViewsLieInTheViewSpaceAndRepeat) {
  const Box3 space = Box3::fromPoints(Vec3(-10, -20, 1), Vec3(30, 5, 2));
  const std::vector<Camera> a = randomViews(space, 200, 4, 64, 48, 45.0f, 0.5f, 1000.0f);
  const std::vector<Camera> b = randomViews(space, 200, 4, 64, 48, 45.0f, 0.5f, 1000.0f);
  ASSERT_EQ(a.size(), 200u);
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_TRUE(space.contains(a[i].eye));
    EXPECT_EQ(a[i].eye, b[i].eye);
    EXPECT_EQ(a[i].at, b[i].at);
    const Vec3 d = glm::normalize(a[i].at - a[i].eye);
    EXPECT_LE(std::abs(std::asin(d.z)), degToRad(10.0) + 1e-5);  // pitch within 10 degrees
    EXPECT_EQ(a[i].width, 64);
  }
}

TEST(CalibrationTest, TheSafetyFactorBoundsTheViewsItCameFrom) {
  CalibrateOptions o = quickOptions(24, CalibrateOptions{}.layered_samples);
  const CalibrateResult r = calibrate(gpu::sharedHeadlessContext(), smallCity(), o);
  ASSERT_EQ(r.checks.size(), 24u);
  EXPECT_GE(r.profile.safety_factor, 1.0);
  EXPECT_EQ(r.over_factor, 0u);  // quantile 1: the largest ratio
  EXPECT_EQ(r.over_bound, 0u);
  size_t over = 0, margin_tight = 0;
  double largest_excess = 0.0;
  for (const ViewCheck& c : r.checks) {
    EXPECT_GT(c.predicted_ms, 0.0);
    EXPECT_GT(c.measured_ms, 0.0);
    over += c.measured_ms > c.predicted_ms * r.profile.safety_factor * (1 + 1e-9) ? 1 : 0;
    // The additive margin bounds every view too, so the profile's bound (the smaller) does.
    EXPECT_LE(c.measured_ms, c.predicted_ms + r.profile.safety_margin_ms + 1e-9);
    EXPECT_LE(c.measured_ms, r.profile.boundOfPrediction(c.predicted_ms) + 1e-9);
    largest_excess = std::max(largest_excess, c.measured_ms - c.predicted_ms);
    margin_tight += c.predicted_ms + r.profile.safety_margin_ms < c.predicted_ms * r.profile.safety_factor;
  }
  EXPECT_EQ(over, 0u);
  EXPECT_NEAR(r.profile.safety_margin_ms, largest_excess, 1e-12);  // the largest, recomputed
  EXPECT_EQ(r.profile.validation["margin_ms"].get<double>(), r.profile.safety_margin_ms);
  std::printf("margin %.3f ms, factor %.3f: the margin is the smaller bound for %zu of 24 views\n",
              r.profile.safety_margin_ms, r.profile.safety_factor, margin_tight);
  EXPECT_LE(r.ratio_p50, r.ratio_max);
  EXPECT_EQ(r.profile.width, 64);
  EXPECT_EQ(r.profile.validation["views"], 24);
  // A lower quantile: the factor is that quantile of measured / predicted (at least 1), recomputed here from the
  // views, and the views above prediction x factor are counted right.
  o.margin_quantile = 0.5;
  const CalibrateResult half = calibrate(gpu::sharedHeadlessContext(), smallCity(), o);
  std::vector<double> ratios;
  for (const ViewCheck& c : half.checks) ratios.push_back(c.measured_ms / c.predicted_ms);
  std::sort(ratios.begin(), ratios.end());
  const double median = 0.5 * (ratios[11] + ratios[12]);  // 24 views: between the 12th and 13th
  EXPECT_NEAR(half.profile.safety_factor, std::max(1.0, median), 1e-9);
  std::vector<double> excess;
  for (const ViewCheck& c : half.checks) excess.push_back(c.measured_ms - c.predicted_ms);
  std::sort(excess.begin(), excess.end());
  EXPECT_NEAR(half.profile.safety_margin_ms, std::max(0.0, 0.5 * (excess[11] + excess[12])), 1e-9);
  size_t above = 0, above_both = 0;
  for (const ViewCheck& c : half.checks) {
    const bool over_factor = c.measured_ms / c.predicted_ms > half.profile.safety_factor;
    above += over_factor ? 1 : 0;
    above_both += over_factor && c.measured_ms - c.predicted_ms > half.profile.safety_margin_ms ? 1 : 0;
  }
  EXPECT_EQ(half.over_factor, above);
  EXPECT_EQ(half.over_bound, above_both);
  EXPECT_LE(above, 12u);
}

// The frame's CPU and GPU terms are fitted on their own measurements: each validation view's predictions are the
// terms' models applied to its workload (recomputed here), the quantiles and counts are those of the views'
// measured / predicted (recomputed), and the profile's validation and the CSV carry them.
TEST(CalibrationTest, TheCpuAndGpuTermsAreFittedAndCheckedOnTheirOwnMeasurements) {
  const CalibrateResult r = calibrate(gpu::sharedHeadlessContext(), smallCity(), quickOptions(16));
  ASSERT_EQ(r.checks.size(), 16u);
  EXPECT_EQ(r.cpu.model.samples, 12u);  // the fitting views
  EXPECT_EQ(r.gpu.model.samples, 12u);
  const double pixels = 64.0 * 64.0;
  size_t cpu_under = 0, gpu_under = 0, wall_under = 0, drawing = 0;
  double cpu_max = 0.0, gpu_max = 0.0, wall_max = 0.0;
  std::vector<double> gpu_ratios;
  for (const ViewCheck& c : r.checks) {
    EXPECT_GE(c.measured_cpu_ms, 0.0);  // wall less the GL calls' time, clamped at 0 (a loaded machine may get there)
    EXPECT_GT(c.measured_gpu_ms, 0.0);
    // Farfield's own CPU time is a part of the frame's wall time, both the minimum of the same single render.
    EXPECT_LE(c.measured_cpu_ms, c.measured_ms);
    const gpu::CostModel& cm = r.cpu.model;
    const double t = double(c.triangles), d = double(c.draw_calls);
    EXPECT_NEAR(c.predicted_cpu_ms, cm.base_ms + cm.ms_per_mtriangle * t / 1e6 + cm.ms_per_draw * d +
                                        cm.ms_per_mpixel * pixels / 1e6, 1e-9);
    const gpu::CostModel& gm = r.gpu.model;
    // The GPU term counts the triangles drawn after the GPU culler's culling: never more than the objects'.
    drawing += c.drawn_triangles > 0;
    EXPECT_LE(c.drawn_triangles, c.triangles);
    const double drawn = double(c.drawn_triangles);
    EXPECT_NEAR(c.predicted_gpu_ms, gm.base_ms + gm.ms_per_mtriangle * drawn / 1e6 + gm.ms_per_draw * d +
                                        gm.ms_per_mpixel * pixels / 1e6, 1e-9);
    cpu_under += c.measured_cpu_ms > c.predicted_cpu_ms;
    gpu_under += c.measured_gpu_ms > c.predicted_gpu_ms;
    const double both = std::max(c.predicted_cpu_ms, c.predicted_gpu_ms);
    wall_under += c.measured_ms > both;
    // A prediction of 0 (a term fitted to nothing) counts as 1e-6 ms, as the calibration takes it.
    cpu_max = std::max(cpu_max, c.measured_cpu_ms / std::max(c.predicted_cpu_ms, 1e-6));
    gpu_max = std::max(gpu_max, c.measured_gpu_ms / std::max(c.predicted_gpu_ms, 1e-6));
    wall_max = std::max(wall_max, c.measured_ms / std::max(both, 1e-6));
    gpu_ratios.push_back(c.measured_gpu_ms / std::max(c.predicted_gpu_ms, 1e-6));
  }
  EXPECT_GT(drawing, 8u) << "most street views draw something";
  EXPECT_EQ(r.cpu.under_predicted, cpu_under);
  EXPECT_EQ(r.gpu.under_predicted, gpu_under);
  EXPECT_EQ(r.max_term.under_predicted, wall_under);
  EXPECT_NEAR(r.cpu.ratio_max, cpu_max, 1e-9 * cpu_max);
  EXPECT_NEAR(r.gpu.ratio_max, gpu_max, 1e-9 * gpu_max);
  EXPECT_NEAR(r.max_term.ratio_max, wall_max, 1e-9 * wall_max);
  std::sort(gpu_ratios.begin(), gpu_ratios.end());
  EXPECT_NEAR(r.gpu.ratio_p50, 0.5 * (gpu_ratios[7] + gpu_ratios[8]), 1e-9);  // 16 views: the 8th and 9th
  EXPECT_LE(r.gpu.ratio_p50, r.gpu.ratio_p95);
  EXPECT_LE(r.gpu.ratio_p95, r.gpu.ratio_max);
  EXPECT_EQ(r.profile.validation["cpu_term"]["ratio_p95"].get<double>(), r.cpu.ratio_p95);
  EXPECT_EQ(r.profile.validation["gpu_term"]["model"]["samples"].get<size_t>(), 12u);
  EXPECT_EQ(r.profile.validation["max_term"]["ratio_max"].get<double>(), r.max_term.ratio_max);

  const std::string csv = ::testing::TempDir() + "/calibration_terms.csv";
  writeCalibrationCsv(r, csv);
  std::ifstream in(csv);
  std::string header, row;
  std::getline(in, header);
  std::getline(in, row);
  EXPECT_NE(header.find(",predicted_cpu_ms,measured_cpu_ms,drawn_triangles,predicted_gpu_ms,measured_gpu_ms"),
            std::string::npos);
  std::vector<double> fields;
  std::stringstream cells(row);
  for (std::string cell; std::getline(cells, cell, ',');) fields.push_back(std::stod(cell));
  ASSERT_EQ(fields.size(), 18u);
  EXPECT_NEAR(fields[14], r.checks[0].measured_cpu_ms, 1e-4 * r.checks[0].measured_cpu_ms);
  EXPECT_EQ(fields[15], double(r.checks[0].drawn_triangles));
  EXPECT_NEAR(fields[17], r.checks[0].measured_gpu_ms, 1e-4 * r.checks[0].measured_gpu_ms);
}

// The fill term (core/object_fill.h) is fitted only when asked; either way each view's estimated fill is reported,
// and with it every prediction is the model's four workload terms and the fill, recomputed here from the coefficients.
TEST(CalibrationTest, TheFillTermIsFittedOnlyWhenAsked) {
  CalibrateOptions o = quickOptions(16);
  const CalibrateResult off = calibrate(gpu::sharedHeadlessContext(), smallCity(), o);
  EXPECT_EQ(off.profile.model.ms_per_mfill, 0.0);
  EXPECT_EQ(off.profile.validation["fill_term"], false);
  o.fill_term = true;
  const CalibrateResult on = calibrate(gpu::sharedHeadlessContext(), smallCity(), o);
  EXPECT_EQ(on.profile.validation["fill_term"], true);
  const gpu::CostModel& m = on.profile.model;
  size_t with_fill = 0;
  for (const ViewCheck& c : on.checks) {
    with_fill += c.fill > 0.0;
    EXPECT_NEAR(c.predicted_ms,
                m.base_ms + m.ms_per_mtriangle * double(c.triangles) * 1e-6 + m.ms_per_draw * double(c.draw_calls) +
                    m.ms_per_mpixel * 64.0 * 64.0 * 1e-6 +
                    m.ms_per_mfill * (m.fill_cap_pixels > 0.0 ? std::min(c.fill, m.fill_cap_pixels) : c.fill) * 1e-6,
                1e-9 * (1.0 + c.predicted_ms));
    EXPECT_LE(c.measured_ms, c.predicted_ms * on.profile.safety_factor * (1 + 1e-9));
  }
  EXPECT_GT(with_fill, 8u);
  // The cap is one of the candidates (2 to 8 frames) or none.
  const double frames = m.fill_cap_pixels / (64.0 * 64.0);
  EXPECT_TRUE(m.fill_cap_pixels == 0.0 || frames == 2.0 || frames == 3.0 || frames == 4.0 || frames == 6.0 ||
              frames == 8.0)
      << frames;
}

// The cap kept is the one whose bound out of sample (each of five folds predicted by the model fitted on the other
// four, bounded by that model's largest ratio, or its largest excess where smaller, over the fold), summed over the
// bounded workloads, is smallest: recomputed here by brute force over the candidates. The samples are built so that
// the region's fills (each view's objects from its region, several frames more) choose another cap than the views'
// own fills.
TEST(CalibrationTest, TheFillCapIsTheOneWhoseHeldOutBoundOverTheRegionsIsSmallest) {
  const double frame = 64.0 * 64.0;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<gpu::CostSample> samples;
  std::vector<double> region_fill;
  for (int i = 0; i < 120; ++i) {
    gpu::CostSample s;
    s.triangles = 2e4 * u(rng);
    s.draw_calls = 5.0 + 40.0 * u(rng);
    s.pixels = frame;
    const bool heavy = i % 10 == 0;
    s.fill = frame * (heavy ? 7.0 + 5.0 * u(rng) : 4.0 * u(rng));
    const double fill_ms = heavy ? 200.0 * s.fill * 1e-6 : 3000.0 * std::min(s.fill, 3.0 * frame) * 1e-6;
    s.ms = 0.5 + 200.0 * s.triangles * 1e-6 + 0.01 * s.draw_calls + fill_ms + 0.3 * u(rng);
    samples.push_back(s);
    region_fill.push_back(s.fill + frame * (6.0 + 6.0 * u(rng)));  // the near buildings, whole frames each
  }
  const auto fitAt = [&](double frames, size_t skip_fold) {
    std::vector<gpu::CostSample> kept;
    for (size_t i = 0; i < samples.size(); ++i)
      if (i % kFillCapFolds != skip_fold) {
        kept.push_back(samples[i]);
        if (frames > 0.0) kept.back().fill = std::min(kept.back().fill, frames * frame);
      }
    gpu::CostModel m = gpu::CostModel::fit(kept);
    m.fill_cap_pixels = frames * frame;
    return m;
  };
  const auto heldOut = [&](double frames, const std::vector<double>& fills) {
    double sum = 0.0;
    for (size_t fold = 0; fold < kFillCapFolds; ++fold) {
      const gpu::CostModel m = fitAt(frames, fold);
      double factor = 1.0, margin = 0.0;
      for (size_t i = 0; i < samples.size(); ++i)
        if (i % kFillCapFolds == fold) {
          const double p = m.predict(samples[i].triangles, samples[i].draw_calls, samples[i].pixels, samples[i].fill);
          factor = std::max(factor, samples[i].ms / p);
          margin = std::max(margin, samples[i].ms - p);
        }
      for (size_t i = 0; i < samples.size(); ++i)
        if (i % kFillCapFolds == fold) {
          const double p = m.predict(samples[i].triangles, samples[i].draw_calls, samples[i].pixels, fills[i]);
          sum += std::min(p * factor, p + margin);
        }
    }
    return sum;
  };
  std::vector<double> own_fill;
  for (const gpu::CostSample& s : samples) own_fill.push_back(s.fill);
  const gpu::CostModel by_region = fitWithFillCap(samples, frame, region_fill);
  const gpu::CostModel by_view = fitWithFillCap(samples, frame);
  for (double frames : {0.0, 2.0, 3.0, 4.0, 6.0, 8.0}) {
    EXPECT_LE(heldOut(by_region.fill_cap_pixels / frame, region_fill), heldOut(frames, region_fill) * (1.0 + 1e-9))
        << frames << " frames";
    EXPECT_LE(heldOut(by_view.fill_cap_pixels / frame, own_fill), heldOut(frames, own_fill) * (1.0 + 1e-9))
        << frames << " frames";
  }
  // The model kept is the one fitted on every sample at that cap.
  const gpu::CostModel all = fitAt(by_region.fill_cap_pixels / frame, kFillCapFolds);
  EXPECT_DOUBLE_EQ(by_region.ms_per_mfill, all.ms_per_mfill);
  EXPECT_DOUBLE_EQ(by_region.base_ms, all.base_ms);
  // The samples tell the two apart: the regions' sums ask for another cap than the views' own.
  EXPECT_NE(by_region.fill_cap_pixels, by_view.fill_cap_pixels);
  EXPECT_THROW(fitWithFillCap(samples, frame, std::vector<double>(3, 0.0)), Error);
  std::printf("caps chosen: %.0f frames over the regions, %.0f over the views\n", by_region.fill_cap_pixels / frame,
              by_view.fill_cap_pixels / frame);
}

// Placed frames: each view's workload is the whole objects of the given visible set that its frustum meets (recounted
// here from the BVH and the scene's per-object costs), and the safety factor still bounds every view.
TEST(CalibrationTest, PlacedFramesCountTheVisibleSetAsPlacementDoes) {
  const scene::Scene& scene = smallCity();
  std::vector<uint32_t> visible;  // every other object
  for (uint32_t id = 1; id <= scene.objects.size(); id += 2) visible.push_back(id);
  CalibrateOptions o = quickOptions(16);
  size_t asked = 0;
  o.visible_set = [&](const Vec3&) -> const std::vector<uint32_t>* {
    ++asked;
    return &visible;
  };
  // Every eye in one region, a box beside the view space's centre: the views' region fill counts from there.
  const Box3 region = Box3::fromPoints(Vec3(-30.0f, -30.0f, 1.0f), Vec3(-10.0f, -10.0f, 2.0f));
  o.region_of = [&](const Vec3&) -> std::optional<Box3> { return region; };
  const CalibrateResult r = calibrate(gpu::sharedHeadlessContext(), scene, o);
  EXPECT_EQ(asked, 28u);
  const FillLens lens = FillLens::of(o.width, o.height, degToRad(double(o.fov_deg)));
  EXPECT_NE(r.profile.validation["frames"].get<std::string>().find("visible set"), std::string::npos);
  EXPECT_NE(r.profile.validation["frames"].get<std::string>().find("runtime (GPU-driven)"), std::string::npos);
  gpu::sharedHeadlessContext().makeCurrent();
  const gpu::GpuScene gpu_scene(scene);
  const std::vector<gpu::ObjectDrawCost> cost = gpu_scene.objectDrawCosts();
  const scene::Bvh bvh(scene);
  size_t seen = 0;
  for (const ViewCheck& c : r.checks) {
    std::vector<uint32_t> ids;
    bvh.queryFrustum(Frustum::fromMatrix(c.camera.viewProjection()), ids);
    uint64_t triangles = 0, draws = 0;
    double region_fill = 0.0;
    for (uint32_t id : ids)
      if (id % 2 == 1) {
        triangles += cost[id].triangles;
        draws += cost[id].draws;
        region_fill += lens.objectPixels(scene.objects[id - 1].world_bounds, region);
      }
    EXPECT_EQ(c.triangles, triangles);
    EXPECT_EQ(c.draw_calls, draws);
    EXPECT_NEAR(c.region_fill, region_fill, 1e-6 * std::max(1.0, region_fill));
    seen += draws > 0;
    EXPECT_LE(c.measured_ms, c.predicted_ms * r.profile.safety_factor * (1 + 1e-9));
  }
  EXPECT_GT(seen, 8u);
}

TEST(CalibrationTest, BadOptionsAreErrors) {
  CalibrateOptions o;
  o.progress = false;
  o.views = 3;
  EXPECT_THROW(calibrate(gpu::sharedHeadlessContext(), smallCity(), o), Error);
  o = CalibrateOptions{};
  o.margin_quantile = 0.0;
  EXPECT_THROW(calibrate(gpu::sharedHeadlessContext(), smallCity(), o), Error);
  o = CalibrateOptions{};
  o.repeats = 0;
  EXPECT_THROW(calibrate(gpu::sharedHeadlessContext(), smallCity(), o), Error);
  o = CalibrateOptions{};
  o.fit_views = 2;
  EXPECT_THROW(calibrate(gpu::sharedHeadlessContext(), smallCity(), o), Error);
  EXPECT_THROW(calibrate(gpu::sharedHeadlessContext(), scene::Scene{}, CalibrateOptions{}), Error);
}

}  // namespace
}  // namespace farfield::eval
