// `farfield crowd bench`: animated crowds on a generated city (Tecchia, Loscos and Chrysanthou's multi-view impostors;
// Steed's lecture part 3). For each crowd size and camera path, three modes run interleaved on the same frames:
// crowd-geometry (every agent in view as skinned instanced geometry: the baseline), crowd-impostor (every agent as a
// multi-view impostor) and crowd-mixed (geometry near, impostors where they keep their promises). Every frame is also
// rendered as the full-geometry reference (every agent skinned, no culling) and each mode is compared with it on the
// crowd's pixels (eval/crowd_metrics.h): PSNR, share over 8/255, popping. The city (view-frustum culled, identical in
// every mode) is drawn first; frame time covers city and crowd, crowd time the crowd pass alone.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "farfield/eval/crowd_walk.h"
#include "farfield/eval/frame_stats.h"
#include "farfield/gpu/context.h"
#include "farfield/runtime/crowd_runtime.h"

namespace farfield::eval {

struct CrowdBenchOptions {
  int blocks = 400;  // the default city: gen city --blocks 400 --detail 2 --seed 1
  int detail = 2;
  uint64_t city_seed = 1;
  std::vector<size_t> agent_counts{1000, 10000};
  uint64_t crowd_seed = 2;
  std::vector<std::string> paths{"pedestrian", "elevated"};
  uint64_t path_seed = 5;
  size_t frames = 8;        // measured frames per run
  size_t frame_step = 15;   // path frames between measured frames (30 fps path: 0.5 s)
  // Passes over the frames, each frame's fastest render kept per mode (the first pass also measures the images).
  int timing_passes = 1;
  int width = 512;
  int height = 512;
  // Skinned glTF files; empty (the default): the built-in figures, a walker and a four-legged one, with their own
  // heights, facings and shares (eval::builtinCrowdModels), so that the bench reads no file.
  std::vector<std::string> models;
  // Per file (used with `models` only); the defaults are the shared models' (CesiumMan, Fox).
  std::vector<float> model_heights = kCrowdModelHeights;
  std::vector<float> model_facing_deg = kCrowdModelFacingDeg;
  std::vector<float> model_shares = kCrowdModelShares;
  runtime::CrowdRuntimeOptions runtime;  // its bound_focal_px is set from the frame size (60 degrees)
  size_t outfits = 32;                   // colour-region outfits drawn from
  bool shadows = true;                   // agents cast shadows (reference and every mode)
  // Every mode leaves out the agents hidden behind the city (CrowdRuntime::cullBehind; its depth read back and
  // reduced inside the crowd pass's time). The reference never culls.
  bool agent_occlusion = false;
  // crowd-mixed's geometry agents cast their shadows as impostors (CrowdShadowOptions::impostor_casters); the
  // reference and crowd-geometry always cast geometry.
  bool impostor_shadows = false;
  runtime::CrowdShadowOptions shadow;
  // Adds crowd-geometry-palette and crowd-mixed-palette: the same policies through a second runtime whose skinned
  // agents blend joint matrices (gpu::Skinning::Palette), timed in the same process on the same frames as the others.
  bool compare_skinning = false;
  // Adds crowd-geometry-gpu, crowd-impostor-gpu and crowd-mixed-gpu: the crowd simulated, culled, classified and
  // drawn on the GPU (gpu/gpu_crowd.h, runtime::CrowdRuntime::drawGpu and drawGpuShadowed; its simulation inside
  // the crowd pass's time), with shadows and agent_occlusion as the others, without budgets yet.
  bool gpu_crowd = false;
  // The city under the crowd: the GPU-driven frame (gpu::GpuCuller over the city's arena, no readback), as the
  // culled mode draws it; city_cpu: culled on the CPU with its occluders' depth read back (the culled-cpu mode).
  bool city_cpu = false;
  std::string out_dir;
  int samples = 2;  // sample frames per run saved (reference, each mode, heat maps)
};

struct CrowdModeResult {
  std::string name;
  FrameSummary wall;   // city + crowd, ms
  FrameSummary crowd;  // crowd pass alone, ms
  // Farfield's own CPU time in the crowd pass: its wall time less the time inside GL calls (gpu/gl_counters.h), ms.
  // The CPU modes' agent states (their poses and phases, CrowdRun::cpu_states_ms) are made before it.
  FrameSummary crowd_cpu;
  // The GPU's time (gpu::StageClock: timestamp queries read after the frame; on a software rasterizer the CPU clock
  // between waits for the GPU, so there about the wall time): the city and the crowd, and the crowd pass alone, ms.
  FrameSummary gpu, crowd_gpu;
  // The crowd pass's GL calls per frame (gpu/gl_counters.h), means: draw calls, bytes uploaded, calls that waited
  // for the GPU (the harness's own wait at the frame's end not counted); syncs_max the most in one frame.
  double draw_calls = 0.0, upload_bytes = 0.0, syncs = 0.0, syncs_max = 0.0;
  double speedup = 0.0;        // median wall of crowd-geometry / this mode's
  double crowd_speedup = 0.0;  // the same on crowd time
  double psnr_mean = 0.0, psnr_min = 0.0, bad_share_mean = 0.0, crowd_pixels_mean = 0.0;
  double popping_mean = 0.0, popping_max = 0.0;
  double geometry_agents = 0.0, impostor_agents = 0.0, in_view = 0.0, triangles = 0.0;  // means per frame
  double occluded = 0.0;  // mean per frame: agents in view left out behind the city (agent_occlusion)
  double over_budget = 0.0;  // mean per frame: impostors inside their switch distance (runtime.max_geometry_triangles)
  double coarser = 0.0;      // mean per frame: geometry agents at a coarser level than the mesh (runtime.geometry_lod_px)
  double coarsened = 0.0;    // mean per frame: of those, coarser than the bound gives them, for the geometry budget
  double shadow_casters = 0.0, shadow_texel_m = 0.0;  // means per frame
  double receiver_bad_pixels = 0.0;  // mean per frame: non-agent pixels off by > 8/255 (shadow differences)
  // With runtime.geometry_ms (crowd-mixed): the measured skinned draws of the frames that drew skinned agents (the
  // fastest of the passes), and how many of them took longer than the budget.
  FrameSummary skinned_ms;
  size_t skinned_over = 0;
};

struct CrowdRun {
  size_t agents = 0;
  std::string path;
  double reference_popping_mean = 0.0;  // the reference's own frame-to-frame change on crowd pixels (MAE)
  double cpu_states_ms = 0.0;  // mean per frame: the CPU modes' agent states (eval::crowdAgentStates), outside the pass
  std::vector<CrowdModeResult> modes;
};

struct CrowdBenchResult {
  std::vector<CrowdRun> runs;
  bool gpu_time_queries = false;  // the GPU times are timestamp queries (else a software rasterizer's CPU clock)
  std::vector<std::string> model_names;
  std::vector<gpu::AtlasLayout> layouts;
  std::vector<runtime::CrowdAtlasChoice> atlas_choices;
  std::vector<size_t> atlas_bytes;
  std::vector<uint64_t> model_triangles;
  std::vector<bool> model_cutout;  // per model: texels cut out (gpu::SkinnedGpuModel::cutout)
  // Per model, per level of detail (level 0 the mesh): triangles and error over the palette (metres; lod_texture).
  std::vector<std::vector<uint64_t>> level_triangles;
  std::vector<std::vector<double>> level_m;
  std::vector<std::vector<double>> level_surface_m, level_texture_m;  // the two parts of level_m (lod_texture)
  double lod_seconds = 0.0;
  std::vector<double> switch_m;  // per model at the bench's camera
  double bake_seconds = 0.0;
  double city_seconds = 0.0;
  uint64_t city_triangles = 0;
  std::string renderer;
  std::string markdown;
};

// Throws farfield::Error for bad options or unreadable models. Writes OUT_DIR/crowd.json, crowd.md and sample
// frames under OUT_DIR/frames when out_dir is set.
CrowdBenchResult runCrowdBench(gpu::Context& context, const CrowdBenchOptions& options);

}  // namespace farfield::eval
