// The layered impostor's costs fitted and validated on this machine (gpu/cost_profile.h, LayeredCost; Jeschke et al.
// 2005, section 3.2: "the rendering time of an impostor ... is estimated by its screen area", since alpha-tested
// layers are fill bound). Sampled on the scene's own clusters: a random eye of the view space, a cluster of objects
// around a random object, a shaft from the cluster towards the eye and the layered plan for it under the error bound
// (impostor/layered.h, as placement and the image cache make them), then
// - capture: captureLayered + cropLayered + the upload (GpuLayeredImpostor), timed once (what a regeneration costs);
// - draw: the impostor alone drawn from a viewpoint of its shaft, minimum of `repeats` renders, less the empty frame
//   (minimum of `repeats` too): what the impostor adds to a frame.
// The fitting samples view each impostor from its capture eye (the nearest viewpoint on the axis); the validation
// samples, other clusters, from random viewpoints of their shafts. Both are predicted from the plan and the view's
// distance alone (layers, impostor::layeredFillPixels, texels, triangles), as placement and the scheduler predict
// them, and each safety factor is the largest measured / predicted over the validation samples.
#pragma once

#include <cstdint>
#include <vector>

#include "farfield/core/bounds.h"
#include "farfield/core/camera.h"
#include "farfield/gpu/cost_profile.h"
#include "farfield/gpu/renderer.h"
#include "farfield/impostor/layered.h"
#include "farfield/scene/scene.h"

namespace farfield::eval {

struct LayeredCalibrateOptions {
  int width = 512;  // the frames (and the bound's pixels)
  int height = 512;
  float fov_deg = 45.0f;
  double error_px = 2.0;
  Box3 view_space;              // eyes; must not be empty
  size_t fit_samples = 40;      // clusters the models are fitted on (at least 8)
  size_t validation_samples = 40;  // other clusters they are checked on (at least 4)
  int repeats = 3;              // renders per draw timing, the minimum kept
  int max_cluster_objects = 16;
  float max_cluster_radius = 40.0f;  // metres: objects whose centres lie this near the seed object join it
  float max_object_size = 150.0f;    // objects larger than this (the ground) never join a cluster
  // Floor of a prediction in the ratios (ms): the difference of two frames is noise below it.
  double noise_floor_ms = 0.25;
  impostor::LayeredOptions layered;
  // The impostors drawn as their tiles, the fill counted over them; false: drawn as whole quads, the fill counted over
  // them (a profile for placement without tiles, PlaceOptions::layer_tiles; comparisons).
  bool layer_tiles = true;
  uint32_t seed = 7;
  bool progress = false;
};

struct LayeredSample {
  Camera view;                // where the draw was timed from
  uint64_t triangles = 0;     // rendered by the capture: the cluster's, once per layer
  uint32_t layers = 0;
  uint64_t texels = 0;        // captured (uncropped plan)
  double fill_pixels = 0.0;   // impostor::layeredFillPixels of the drawn (cropped, tiled) layers at the view's distance
  double capture_ms = 0.0;    // measured
  double draw_ms = 0.0;       // measured: impostor frame less empty frame, >= 0
  // The same impostor from the same view drawn the other way (whole quads when the layers are drawn as their tiles,
  // and the reverse), timed in the same renders' loop: what the tiles save, measured.
  double draw_other_ms = 0.0;
  double capture_predicted_ms = 0.0;  // raw model (validation samples)
  double draw_predicted_ms = 0.0;
};

struct LayeredCalibrateResult {
  gpu::LayeredCost cost;
  std::vector<LayeredSample> fit, checks;
  // measured / max(predicted, noise floor) over the validation samples
  double draw_ratio_p50 = 0, draw_ratio_p95 = 0, draw_ratio_max = 0;
  double capture_ratio_p50 = 0, capture_ratio_p95 = 0, capture_ratio_max = 0;
  // Over every sample: draw time as tiles / as whole quads, per sample (median) and summed.
  double tiles_over_whole_p50 = 0, tiles_over_whole_sum = 0;
  size_t skipped = 0;  // clusters drawn whose plan could not keep the bound or did not clear the cluster
  double wall_s = 0.0;
};

// Needs a current context. Throws farfield::Error for bad options or a scene with too few usable clusters.
LayeredCalibrateResult calibrateLayered(gpu::Renderer& renderer, const gpu::GpuScene& gpu_scene,
                                        const scene::Scene& scene, const LayeredCalibrateOptions& options);

}  // namespace farfield::eval
