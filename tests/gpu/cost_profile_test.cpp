// The cost profile (gpu/cost_profile.h): saved whole and read back strictly; the bound is the prediction times the
// safety factor, or plus the margin where that is smaller, and one factor at a budget decides as that bound does.
#include "farfield/gpu/cost_profile.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>

#include "farfield/core/error.h"
#include "support/test_support.h"

namespace farfield::gpu {
namespace {

CostProfile oddProfile() {
  CostProfile p;
  p.model.base_ms = 1.25;
  p.model.ms_per_mtriangle = 3.5;
  p.model.ms_per_draw = 0.0625;
  p.model.ms_per_mpixel = 0.75;
  p.model.ms_per_mfill = 2.5;
  p.model.fill_cap_pixels = 3e6;
  p.model.samples = 17;
  p.model.rms_error_ms = 0.5;
  p.model.r2 = 0.875;
  p.safety_factor = 1.5;
  p.safety_margin_ms = 12.0;  // the factor's bound is the smaller up to predictions of 24 ms
  p.width = 640;
  p.height = 360;
  p.fov_y_deg = 52.5;
  p.renderer = "test renderer";
  p.validation = {{"views", 500}};
  p.layered.calibrated = true;
  p.layered.draw.base_ms = 0.125;
  p.layered.draw.ms_per_draw = 0.25;
  p.layered.draw.ms_per_mpixel = 4.0;
  p.layered.capture.ms_per_mtriangle = 8.0;
  p.layered.capture.ms_per_draw = 0.5;
  p.layered.capture.ms_per_mpixel = 16.0;
  p.layered.draw_safety_factor = 2.0;
  p.layered.capture_safety_factor = 1.25;
  p.layered.validation = {{"draw_samples", 40}};
  return p;
}

TEST(CostProfileTest, RoundTripAndBound) {
  const std::string file = (test::scratchDir("cost_profile") / "profile.json").string();
  const CostProfile p = oddProfile();
  saveCostProfile(p, file);
  const CostProfile q = loadCostProfile(file);
  EXPECT_EQ(q.toJson(), p.toJson());
  // By hand: (1.25 + 3.5 * 2 + 0.0625 * 100 + 0.75 * 1 + 2.5 * 2) * 1.5, and the fill counted up to its cap of 3.
  EXPECT_DOUBLE_EQ(q.boundMs(2e6, 100, 1e6, 2e6), (1.25 + 7.0 + 6.25 + 0.75 + 5.0) * 1.5);
  EXPECT_DOUBLE_EQ(q.boundMs(2e6, 100, 1e6, 4e6), (1.25 + 7.0 + 6.25 + 0.75 + 7.5) * 1.5);
  // The layered terms by hand: draw (0.125 + 0.25 * 10 + 4 * 0.5) * 2; capture (8 * 1 + 0.5 * 10 + 16 * 0.25) * 1.25.
  EXPECT_DOUBLE_EQ(q.layered.drawBoundMs(10, 5e5), (0.125 + 2.5 + 2.0) * 2.0);
  EXPECT_DOUBLE_EQ(q.layered.captureBoundMs(1e6, 10, 2.5e5), (8.0 + 5.0 + 4.0) * 1.25);
  // Not calibrated: no layered cost, saved as null and read back so.
  CostProfile none = p;
  none.layered = {};
  saveCostProfile(none, file);
  const CostProfile r = loadCostProfile(file);
  EXPECT_FALSE(r.layered.calibrated);
  EXPECT_EQ(r.layered.drawBoundMs(10, 5e5), 0.0);
  EXPECT_TRUE(r.toJson()["layered"].is_null());
}

TEST(CostProfileTest, TheBoundIsTheSmallerOfTheFactorAndTheMargin) {
  CostProfile p = oddProfile();
  EXPECT_DOUBLE_EQ(p.boundOfPrediction(10.0), 15.0);   // x 1.5 (22 with the margin)
  EXPECT_DOUBLE_EQ(p.boundOfPrediction(24.0), 36.0);   // both
  EXPECT_DOUBLE_EQ(p.boundOfPrediction(40.0), 52.0);   // + 12 (60 with the factor)
  EXPECT_DOUBLE_EQ(p.boundMs(2e7, 100, 1e6, 4e7), 1.25 + 70.0 + 6.25 + 0.75 + 7.5 + 12.0);  // 85.75 predicted
  p.safety_margin_ms = std::numeric_limits<double>::infinity();  // none: the factor alone
  EXPECT_DOUBLE_EQ(p.boundOfPrediction(40.0), 60.0);
}

// At a budget t the profile folded to one factor gives the bound's verdict for every prediction: brute force over
// predictions and budgets, with and without a margin, and with a margin above the budget.
TEST(CostProfileTest, OneFactorAtABudgetDecidesAsTheBound) {
  for (double margin : {0.0, 0.8, 3.0, 12.0, std::numeric_limits<double>::infinity()}) {
    CostProfile p = oddProfile();
    p.safety_margin_ms = margin;
    for (double t : {1.0, 2.5, 8.0, 10.0, 24.0, 100.0}) {
      const CostProfile at = p.atBudget(t);
      EXPECT_GE(at.safety_factor, 1.0);
      EXPECT_LE(at.safety_factor, p.safety_factor);
      EXPECT_FALSE(std::isfinite(at.safety_margin_ms));
      for (int k = 1; k <= 4000; ++k) {
        const double predicted = 0.01 * k;
        const double exact = p.boundOfPrediction(predicted), folded = at.boundOfPrediction(predicted);
        // The same verdict away from the edge (a hair's rounding at it).
        if (std::abs(exact - t) > 1e-9 && std::abs(folded - t) > 1e-9) {
          EXPECT_EQ(exact <= t, folded <= t) << "margin " << margin << " t " << t << " prediction " << predicted;
        }
        if (folded < t) {
          EXPECT_LE(folded, exact + 1e-12);  // scaled: at most the bound under t
        }
        if (folded > t) {
          EXPECT_GE(folded, exact - 1e-12);  // and at least over it
        }
      }
    }
  }
}

TEST(CostProfileTest, VersionThreeHasNoMargin) {
  nlohmann::json j = oddProfile().toJson();
  j["version"] = 3;
  j.erase("safety_margin_ms");
  const CostProfile p = CostProfile::fromJson(j, "v3.json");
  EXPECT_FALSE(std::isfinite(p.safety_margin_ms));
  EXPECT_DOUBLE_EQ(p.boundOfPrediction(40.0), 60.0);
  j["safety_margin_ms"] = 1.0;  // a key version 3 did not have
  EXPECT_THROW(CostProfile::fromJson(j, "v3.json"), Error);
  // Version 4 without a margin: null, read back as none.
  CostProfile none = oddProfile();
  none.safety_margin_ms = std::numeric_limits<double>::infinity();
  const nlohmann::json k = none.toJson();
  EXPECT_TRUE(k["safety_margin_ms"].is_null());
  EXPECT_FALSE(std::isfinite(CostProfile::fromJson(k, "v4.json").safety_margin_ms));
}

TEST(CostProfileTest, VersionOneHasNoLayeredTerms) {
  nlohmann::json j = oddProfile().toJson();
  j["version"] = 1;
  j.erase("layered");
  j.erase("safety_margin_ms");
  j["model"].erase("ms_per_mfill");
  j["model"].erase("fill_cap_pixels");
  const CostProfile p = CostProfile::fromJson(j, "old.json");
  EXPECT_FALSE(p.layered.calibrated);
  EXPECT_DOUBLE_EQ(p.model.ms_per_draw, 0.0625);
  j["layered"] = nullptr;  // a key version 1 did not have
  EXPECT_THROW(CostProfile::fromJson(j, "old.json"), Error);
}

TEST(CostProfileTest, VersionTwoHasNoFillTerm) {
  nlohmann::json j = oddProfile().toJson();
  j["version"] = 2;
  j.erase("safety_margin_ms");
  for (nlohmann::json* m : {&j["model"], &j["layered"]["draw"], &j["layered"]["capture"]}) {
    m->erase("ms_per_mfill");
    m->erase("fill_cap_pixels");
  }
  const CostProfile p = CostProfile::fromJson(j, "v2.json");
  EXPECT_EQ(p.model.ms_per_mfill, 0.0);
  EXPECT_DOUBLE_EQ(p.boundMs(2e6, 100, 1e6, 4e6), (1.25 + 7.0 + 6.25 + 0.75) * 1.5);  // the fill predicts nothing
  EXPECT_TRUE(p.layered.calibrated);
  j["model"]["ms_per_mfill"] = 1.0;  // a key version 2 did not have
  EXPECT_THROW(CostProfile::fromJson(j, "v2.json"), Error);
}

TEST(CostProfileTest, StrictReadNamesTheKey) {
  const nlohmann::json good = oddProfile().toJson();
  const auto expectError = [](const nlohmann::json& j, const std::string& part) {
    try {
      CostProfile::fromJson(j, "profile.json");
      ADD_FAILURE() << "expected an error naming " << part;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("profile.json"), std::string::npos) << e.what();
    }
  };
  nlohmann::json j = good;
  j["extra"] = 1;
  expectError(j, "extra");
  j = good;
  j.erase("safety_factor");
  expectError(j, "safety_factor");
  j = good;
  j["safety_factor"] = 0.5;  // a bound below the prediction
  expectError(j, "safety_factor");
  j = good;
  j["model"]["ms_per_draw"] = -1.0;
  expectError(j, "ms_per_draw");
  j = good;
  j["model"]["colour"] = 1;
  expectError(j, "colour");
  j = good;
  j["version"] = 5;
  expectError(j, "version");
  j = good;
  j["safety_margin_ms"] = -0.5;
  expectError(j, "safety_margin_ms");
  j = good;
  j.erase("safety_margin_ms");
  expectError(j, "safety_margin_ms");
  j = good;
  j["model"].erase("ms_per_mfill");
  expectError(j, "ms_per_mfill");
  j = good;
  j["model"]["fill_cap_pixels"] = -1.0;
  expectError(j, "fill_cap_pixels");
  j = good;
  j.erase("layered");
  expectError(j, "layered");
  j = good;
  j["layered"]["draw_safety_factor"] = 0.5;
  expectError(j, "draw_safety_factor");
  j = good;
  j["layered"]["capture"]["ms_per_mpixel"] = -1.0;
  expectError(j, "layered.capture");
  j = good;
  j["format"] = "something";
  expectError(j, "format");
  j = good;
  j["width"] = "wide";
  expectError(j, "width");
  // Numbers beyond the fields' integer types (converting them was undefined behaviour), and fractions of a pixel.
  j = good;
  j["width"] = 1e300;
  expectError(j, "\"width\": 1.0000000000000001e+300 is out of range");
  j = good;
  j["height"] = 4294967296.0;
  expectError(j, "\"height\"");
  j = good;
  j["height"] = 360.5;
  expectError(j, "\"height\": 360.5 is not a whole number");
  j = good;
  j["model"]["samples"] = 1e300;
  expectError(j, "model: \"samples\"");
  EXPECT_THROW(loadCostProfile((test::scratchDir("cost_profile_missing") / "none.json").string()), Error);
  const std::string garbage = (test::scratchDir("cost_profile_garbage") / "bad.json").string();
  std::ofstream(garbage) << "{not json";
  EXPECT_THROW(loadCostProfile(garbage), Error);
}

}  // namespace
}  // namespace farfield::gpu
