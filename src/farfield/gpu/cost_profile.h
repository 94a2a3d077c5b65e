// The machine's cost profile: the cost model fitted on this machine (gpu/cost_model.h), the frame it was fitted
// for, and the safety factor measured when it was validated against frames of the view space (eval/calibration.h,
// `farfield calibrate`). Placement (Jeschke et al. 2005, section 3) bounds a view's time by
// predict(...) * safety_factor, so the frame-time guarantee rests on a measured distribution, stated in the profile.
// Since version 4 the profile also holds an additive margin, the largest measured - predicted of the same views, and
// the bound is the smaller of the two: min(prediction * safety_factor, prediction + safety_margin_ms). Both hold for
// every validation view, so their minimum does too; the factor is the tighter one for light frames, the margin for
// the heavy frames near a budget (a multiplicative factor set by a 2 ms view that measured 4 ms charges a 9 ms
// prediction 18 ms).
//
// Layered impostors (impostor/layered.h) cost what the linear frame model does not see: every alpha-tested layer is
// filled over its whole quad, transparent texels included, and regenerating one renders, reads back, crops and
// uploads one image per layer. LayeredCost holds two more linear models for them, fitted and validated on this machine
// (eval/layered_calibration.h), each with its own safety factor.
//
// Saved whole and read back strictly: a missing or unknown key, or a value of the wrong type or out of range, is a
// farfield::Error naming the file and the key. Version 1 profiles (before the layered terms) are read with
// LayeredCost::calibrated false; version 2 has the key "layered" (null when not calibrated); version 3 has the fill
// term (CostModel::ms_per_mfill, fill_cap_pixels) in every model, read as 0 from earlier versions; version 4 has
// "safety_margin_ms" (a number, or null for none), read as none from earlier versions.
#pragma once

#include <algorithm>
#include <limits>
#include <string>

#include <nlohmann/json.hpp>

#include "farfield/gpu/cost_model.h"

namespace farfield::gpu {

inline constexpr char kCostProfileFormat[] = "farfield-cost-profile";
inline constexpr int kCostProfileVersion = 4;

// The layered impostor's two costs. The models reuse CostModel's four columns with these meanings:
// - draw: ms added to a frame by drawing one layered impostor = base + ms_per_draw * layers + ms_per_mpixel * the
//   frame pixels its quads cover (impostor::layeredFillPixels; transparent texels included); triangles unused (0);
// - capture: ms of one regeneration (captureLayered, cropLayered, upload) = base + ms_per_mtriangle * triangles
//   rendered (the cluster's, once per layer) + ms_per_draw * layers + ms_per_mpixel * texels captured.
struct LayeredCost {
  bool calibrated = false;  // false: no layered terms (a version-1 profile); every prediction is 0
  CostModel draw;
  CostModel capture;
  double draw_safety_factor = 1.0;     // >= 1: measured / predicted over the validation samples (the largest)
  double capture_safety_factor = 1.0;  // >= 1
  nlohmann::json validation = nlohmann::json::object();  // samples and quantiles; informative

  // Upper bounds (prediction x factor), ms; 0 when not calibrated.
  double drawBoundMs(double layers, double fill_pixels) const {
    return calibrated ? draw.predict(0.0, layers, fill_pixels) * draw_safety_factor : 0.0;
  }
  double captureBoundMs(double triangles, double layers, double texels) const {
    return calibrated ? capture.predict(triangles, layers, texels) * capture_safety_factor : 0.0;
  }
  nlohmann::json toJson() const;  // null when not calibrated
  static LayeredCost fromJson(const nlohmann::json& json, const std::string& source, int version);
};

struct CostProfile {
  CostModel model;
  double safety_factor = 1.0;  // >= 1: bound = prediction * safety_factor ...
  // ... or prediction + safety_margin_ms where that is smaller (>= 0; infinity: no additive margin).
  double safety_margin_ms = std::numeric_limits<double>::infinity();
  int width = 512;             // the frames it was fitted and validated on
  int height = 512;
  double fov_y_deg = 45.0;
  std::string renderer;        // GL_RENDERER of the machine
  // The validation it was derived from (views, quantiles of measured / predicted); informative, kept whole.
  nlohmann::json validation = nlohmann::json::object();
  LayeredCost layered;

  // An upper bound of the frame time (ms) of a workload, in the units of CostSample (fill: core/object_fill.h).
  double boundMs(double triangles, double draw_calls, double pixels, double fill) const {
    return boundOfPrediction(model.predict(triangles, draw_calls, pixels, fill));
  }
  double boundOfPrediction(double predicted_ms) const {
    return std::min(predicted_ms * safety_factor, predicted_ms + safety_margin_ms);
  }
  // The one factor that decides a budget as the bound does: prediction * safetyFactorAt(t) <= t exactly when
  // boundOfPrediction(prediction) <= t (t > 0). It is safety_factor, or t / (t - margin) where that is smaller.
  double safetyFactorAt(double t_max_ms) const {
    if (!(t_max_ms > safety_margin_ms)) return safety_factor;
    return std::min(safety_factor, t_max_ms / (t_max_ms - safety_margin_ms));
  }
  // This profile at one frame budget: the margin folded into the factor (safetyFactorAt), so the bound is linear again
  // and per-object costs add up as placement sums them, with the same verdict at t_max for every workload. Bounds away
  // from t_max are scaled: under t_max they are at most the true bound, over it at least.
  CostProfile atBudget(double t_max_ms) const {
    CostProfile p = *this;
    p.safety_factor = safetyFactorAt(t_max_ms);
    p.safety_margin_ms = std::numeric_limits<double>::infinity();
    return p;
  }
  nlohmann::json toJson() const;
  static CostProfile fromJson(const nlohmann::json& json, const std::string& source);
};

void saveCostProfile(const CostProfile& profile, const std::string& path);
// Throws farfield::Error naming the file for a missing, unreadable or malformed profile.
CostProfile loadCostProfile(const std::string& path);

}  // namespace farfield::gpu
