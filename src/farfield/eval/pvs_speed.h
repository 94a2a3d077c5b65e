// The PVS sampler's speed with and without occlusion culling, measured in one process on the same viewpoints, and
// whether the ids seen agree (they must: the culling is exact). `farfield pvs-speed` wires it to the command line.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "farfield/core/math.h"
#include "farfield/gpu/renderer.h"
#include "farfield/urban/pvs.h"

namespace farfield::eval {

struct PvsSpeedOptions {
  urban::PvsOptions pvs;                     // face size and planes; reuse and the culling flags are set per run
  std::vector<double> occluder_shares{0.1};  // one culled run per share
  int repeats = 1;                           // renders per viewpoint and run, the fastest kept
};

struct PvsSpeedRun {
  bool occlusion = false;
  double occluder_share = 0.0;
  double ms = 0.0;  // all viewpoints, fastest repeat each
  uint64_t triangles_drawn = 0;
  uint64_t objects_hidden = 0;  // summed over the faces
  size_t mismatched_points = 0;  // viewpoints whose ids differ from the unculled run's
  size_t ids_missing = 0, ids_extra = 0;
};

struct PvsSpeedReport {
  size_t points = 0;
  uint64_t scene_triangles = 0;
  std::vector<PvsSpeedRun> runs;  // runs[0]: no occlusion culling (the reference)
  nlohmann::json toJson() const;
};

// 360-degree item-buffer views (urban::PvsSampler::sampleViewpoint) from every eye, by each run in turn per eye (the
// reference first, then the culled runs: the same load for all), timed with the GPU finished.
PvsSpeedReport measurePvsSpeed(const gpu::GpuScene& scene, std::span<const Vec3> eyes,
                               const PvsSpeedOptions& options);

}  // namespace farfield::eval
