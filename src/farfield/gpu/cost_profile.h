// The machine's cost profile: the cost model fitted on this machine (gpu/cost_model.h), the frame it was fitted
// for, and the safety factor measured when it was validated against frames of the view space (eval/calibration.h,
// `farfield calibrate`). Placement (Jeschke et al. 2005, section 3) bounds a view's time by
// predict(...) * safety_factor, so the frame-time guarantee rests on a measured distribution, stated in the profile.
//
// Saved whole and read back strictly: a missing or unknown key, or a value of the wrong type or out of range, is a
// farfield::Error naming the file and the key.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "farfield/gpu/cost_model.h"

namespace farfield::gpu {

inline constexpr char kCostProfileFormat[] = "farfield-cost-profile";
inline constexpr int kCostProfileVersion = 1;

struct CostProfile {
  CostModel model;
  double safety_factor = 1.0;  // >= 1: bound = prediction * safety_factor
  int width = 512;             // the frames it was fitted and validated on
  int height = 512;
  double fov_y_deg = 45.0;
  std::string renderer;        // GL_RENDERER of the machine
  // The validation it was derived from (views, quantiles of measured / predicted); informative, kept whole.
  nlohmann::json validation = nlohmann::json::object();

  // An upper bound of the frame time (ms) of a workload, in the units of CostSample.
  double boundMs(double triangles, double draw_calls, double pixels) const {
    return model.predict(triangles, draw_calls, pixels) * safety_factor;
  }
  nlohmann::json toJson() const;
  static CostProfile fromJson(const nlohmann::json& json, const std::string& source);
};

void saveCostProfile(const CostProfile& profile, const std::string& path);
// Throws farfield::Error naming the file for a missing, unreadable or malformed profile.
CostProfile loadCostProfile(const std::string& path);

}  // namespace farfield::gpu
