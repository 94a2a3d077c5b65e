// The options of a bake that every extractor stage shares (capture resolution and field of view, eye height, clip
// planes, mesh construction, workers), and where a street cell's creation camera stands (Sillion et al. 1997,
// section 4.2: at the edge origin, looking along the street).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "farfield/core/camera.h"
#include "farfield/impostor/capture.h"
#include "farfield/impostor/depth_mesh.h"
#include "farfield/urban/cells.h"

namespace farfield::extract {

struct BakeOptions {
  int resolution = 512;      // impostor image width = height, pixels
  // Vertical = horizontal field of view of the creation camera. The walker's 60 degrees: on the default city's
  // 600 m drive (10 cells, 100 frames, 512 x 512) wider captures lose more to the coarser texture than they gain in
  // coverage (depth-mesh PSNR 36.8 dB at 60, 36.5 at 75, 35.6 at 90, 35.4 at 110 degrees; cracks 1.1% for all):
  // with the street cell lookup the view rarely turns far from the street's direction within a cell.
  float fov_deg = 60.0f;
  float eye_height = 1.7f;   // metres above the ground under the edge's ends (a pedestrian)
  float near_plane = 0.5f;   // metres
  float far_plane = 20000.0f;
  impostor::CaptureOptions capture;
  impostor::DepthMeshOptions depth_mesh;  // its resolution and fov_y are overridden by the two above
  int workers = 0;            // CPU threads building meshes; 0 = hardware threads - 1, at least 1
  size_t queue_capacity = 2;  // captures waiting for a worker
  bool progress = true;       // progress bar on stderr (also off with FF_PROGRESS=0)
  std::string scene_label;    // recorded in the store's index
};

// Where the creation camera of a cell stands and looks: at the edge origin, `eye_height` above the ground there,
// looking at the edge end at the same height above the ground there. `ground` gives the ground height at (x, y).
// Throws farfield::Error for a degenerate cell.
Camera cellCamera(const urban::CellMap& cells, uint32_t cell, const BakeOptions& options,
                  const std::function<float(float, float)>& ground);

// Throws farfield::Error naming the option for a value out of range (resolution, field of view, planes, workers).
void validateBakeOptions(const BakeOptions& options);

}  // namespace farfield::extract
