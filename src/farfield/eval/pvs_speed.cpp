#include "farfield/eval/pvs_speed.h"

#include <algorithm>
#include <limits>
#include <memory>

#include <nlohmann/json.hpp>

#include "farfield/core/error.h"
#include "farfield/core/timer.h"

namespace farfield::eval {

PvsSpeedReport measurePvsSpeed(const gpu::GpuScene& scene, std::span<const Vec3> eyes,
                               const PvsSpeedOptions& options) {
  if (eyes.empty()) throw Error("pvs-speed", "no viewpoints");
  if (options.repeats < 1) throw Error("pvs-speed", "repeats must be at least 1");
  PvsSpeedReport report;
  report.points = eyes.size();
  for (const gpu::GpuMesh& mesh : scene.meshes()) report.scene_triangles += mesh.indexCount() / 3;

  std::vector<std::unique_ptr<urban::PvsSampler>> samplers;
  urban::PvsOptions base = options.pvs;
  base.reuse_viewpoints = false;
  base.occlusion_culling = false;
  samplers.push_back(std::make_unique<urban::PvsSampler>(scene, base));
  report.runs.push_back({});
  for (double share : options.occluder_shares) {
    urban::PvsOptions culled = base;
    culled.occlusion_culling = true;
    culled.occluder_share = share;
    samplers.push_back(std::make_unique<urban::PvsSampler>(scene, culled));
    report.runs.push_back({true, share});
  }

  std::vector<uint8_t> reference, seen;
  for (const Vec3& eye : eyes) {
    for (size_t r = 0; r < samplers.size(); ++r) {
      PvsSpeedRun& run = report.runs[r];
      double best = std::numeric_limits<double>::infinity();
      urban::ViewpointStats stats;
      for (int k = 0; k < options.repeats; ++k) {
        seen.clear();
        Stopwatch timer;
        stats = samplers[r]->sampleViewpoint(eye, seen);  // reads the ids back: the GPU has finished
        best = std::min(best, timer.milliseconds());
      }
      run.ms += best;
      run.triangles_drawn += stats.triangles_drawn;
      run.objects_hidden += stats.objects_hidden;
      if (r == 0) {
        reference = seen;
        continue;
      }
      const size_t n = std::max(reference.size(), seen.size());
      bool same = true;
      for (size_t id = 1; id < n; ++id) {
        const bool want = id < reference.size() && reference[id], got = id < seen.size() && seen[id];
        if (want == got) continue;
        same = false;
        ++(want ? run.ids_missing : run.ids_extra);
      }
      run.mismatched_points += same ? 0 : 1;
    }
  }
  return report;
}

nlohmann::json PvsSpeedReport::toJson() const {
  nlohmann::json j;
  j["points"] = points;
  j["scene_triangles"] = scene_triangles;
  nlohmann::json list = nlohmann::json::array();
  for (const PvsSpeedRun& r : runs) {
    list.push_back({{"occlusion", r.occlusion},
                    {"occluder_share", r.occluder_share},
                    {"ms", r.ms},
                    {"ms_per_point", points ? r.ms / double(points) : 0.0},
                    {"speedup", r.ms > 0.0 ? runs.front().ms / r.ms : 0.0},
                    {"triangles_drawn", r.triangles_drawn},
                    {"objects_hidden", r.objects_hidden},
                    {"mismatched_points", r.mismatched_points},
                    {"ids_missing", r.ids_missing},
                    {"ids_extra", r.ids_extra}});
  }
  j["runs"] = list;
  return j;
}

}  // namespace farfield::eval
