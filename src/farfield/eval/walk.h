// `farfield walk`: one mode along a camera path, every frame timed (see frame_runner.h), with a per-frame CSV,
// optional frame PNGs and a summary (median, p95, p99, max; percentiles as in frame_stats.h).
#pragma once

#include <map>
#include <string>
#include <vector>

#include "farfield/eval/frame_runner.h"
#include "farfield/eval/frame_stats.h"
#include "farfield/gen/camera_path.h"
#include "farfield/gpu/context.h"
#include "farfield/scene/scene.h"

namespace farfield::eval {

struct WalkOptions {
  std::string mode = "full";
  int width = 640;
  int height = 360;
  size_t frames = 0;        // the first N frames of the path; 0 = all
  std::string frames_dir;   // when set, frame PNGs (frame_00000.png, ...) every `every` frames go here
  int every = 10;           // >= 1
  std::map<std::string, std::string> mode_options;  // ModeContext::options
  float near_plane = 0.5f;  // metres
  float far_plane = 20000.0f;
  bool warm_up = true;      // render the first frame once, untimed, before measuring
};

struct WalkResult {
  std::string mode;
  std::string renderer;  // Context::description()
  int width = 0;
  int height = 0;
  std::vector<FrameRecord> frames;
  FrameSummary wall;  // over FrameRecord::wall_ms
  FrameSummary gpu;   // over FrameRecord::gpu_ms
  FrameSummary cpu;   // over FrameRecord::cpu_ms (Farfield's own CPU time)
  CallSummary calls;  // GL calls, uploads and synchronisations
  double mean_triangles = 0.0;
  double mean_draw_calls = 0.0;
  double mean_objects = 0.0;
  std::vector<std::string> written_frames;  // PNG paths
  std::map<std::string, double> info;       // the mode's Mode::info() after the walk
};

// Makes the context current and runs the walk. Throws farfield::Error for an unknown mode (listing the known ones),
// bad options, an empty path or an unusable camera in it.
WalkResult runWalk(gpu::Context& context, const scene::Scene& scene, const gen::CameraPath& path,
                   const WalkOptions& options);

// frame,path_frame,mode,wall_ms,gpu_ms,triangles,draw_calls,objects,cpu_ms,driver_ms,gl_calls,dispatches,
// upload_bytes,syncs,impostors,governor_level,predicted_ms,corrected_ms,bound_scale (one row per measured frame;
// impostors 1 or 0, empty for a mode that draws none by design; the governor's columns empty for a mode without one).
void writeWalkCsv(const WalkResult& result, const std::string& file);
// A few human-readable lines: mode, size, frames, median/p95/p99/max wall and GPU ms, mean triangles/draw calls.
std::string formatWalkSummary(const WalkResult& result);

}  // namespace farfield::eval
