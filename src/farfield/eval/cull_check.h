// The GPU-driven frame checked against the frustum-culled frame on every frame of a camera path (issue "A GPU-driven
// frame", done-when: identical item buffers where they are visible, PSNR at least 60 dB).
//
// Per frame: the reference is every cluster in the frustum drawn by gpu::Renderer (GpuScene's culled items, which
// draw the frame of all objects), twice: first drawn wins ties in depth, then last drawn wins. Pixels where the two
// differ show coplanar surfaces of different objects, whose winner depends on draw order in any renderer (tie
// pixels). The GPU-culled frame (gpu::GpuCuller, its history carried from frame to frame as in a walk) must then show
// the reference's object at every other pixel; a cluster that the occlusion test dropped while visible shows as a
// differing pixel. The colour is compared with PSNR over all pixels; the pixels where only the colour depends on draw
// order (coplanar faces of one object) are counted too, as what may lower it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "farfield/gen/camera_path.h"
#include "farfield/gpu/context.h"
#include "farfield/gpu/gpu_culler.h"
#include "farfield/scene/scene.h"

namespace farfield::eval {

struct CullCheckOptions {
  int width = 640;
  int height = 360;
  size_t stride = 1;  // every stride-th path frame
  size_t frames = 0;  // at most this many (0: all)
  float near_plane = 0.5f;
  float far_plane = 20000.0f;
  gpu::GpuCullOptions cull;
  double min_psnr_db = 60.0;  // the check's colour threshold
};

struct CullCheckFrame {
  size_t path_frame = 0;
  uint64_t differing = 0;   // pixels whose object differs from the reference's, tie pixels left out
  uint64_t ties = 0;        // pixels whose object depends on draw order
  uint64_t colour_ties = 0;  // other pixels whose colour does (coplanar faces of one object: a window on a wall)
  double psnr_db = 0.0;     // colour against the reference (99 for identical)
  uint64_t reference_triangles = 0;  // drawn by the reference (clusters in the frustum, not facing away)
};

struct CullCheckResult {
  std::string renderer;
  int width = 0, height = 0;
  std::vector<CullCheckFrame> frames;
  size_t frames_differing = 0;  // frames with a differing pixel
  uint64_t differing_max = 0;
  double psnr_db_min = 0.0;
  double tie_share_mean = 0.0;  // of the pixels
  double colour_tie_share_mean = 0.0;
  bool passed = false;          // no differing pixel and every PSNR at least min_psnr_db
};

// Makes the context current and runs the check. Throws farfield::Error for an empty path or an unusable camera.
CullCheckResult runCullCheck(gpu::Context& context, const scene::Scene& scene, const gen::CameraPath& path,
                             const CullCheckOptions& options);
// cullcheck.json (the summary and every frame) and cullcheck.md into out_dir (created if missing).
void writeCullCheck(const CullCheckResult& result, const std::string& scene_label, const std::string& path_label,
                    const std::string& out_dir);

}  // namespace farfield::eval
