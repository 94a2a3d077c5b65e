// Rendering the distant model into the impostor's colour and depth images (Sillion et al. 1997, section 4.2,
// "Creation of the impostor image"), with the paper's special colour for bottom faces seen from below.
//
// Why two renders instead of a shader flag: the paper colours the bottom faces of ground elements specially. The
// renderer has no notion of "ground" or of colouring back faces, and the gpu module is not ours to change here.
// What the paper needs to know is where the view ray first meets the underside of a surface, which happens exactly
// where a surface is seen from its back. Rendering once more with every material double-sided and comparing depths
// finds those pixels: with the same vertices and the same transform a front face rasterises to the same depth in
// both renders, so only back faces (culled in the first render) come out nearer in the second. Materials that are
// already double-sided (foliage, thin walls) look the same in both and are never marked. The second render is an
// item-buffer render (depth and ids only, no texture sampling), so a single-sided textured material with cut-out
// texels (alpha below 0.5) is solid there: where such a cut-out is the first surface along a ray, the pixel is
// wrongly marked. The procedural city has no cut-out textures.
#include "farfield/impostor/capture.h"

#include <unordered_map>
#include <vector>

#include "farfield/core/timer.h"
#include "farfield/gpu/render_target.h"
#include "farfield/impostor/contour.h"

namespace farfield::impostor {

ImpostorCapture captureView(gpu::Renderer& renderer, const gpu::GpuScene& scene,
                            std::span<const uint32_t> object_ids, const Camera& camera,
                            const CaptureOptions& options) {
  camera.validate("impostor camera");
  Stopwatch timer;
  std::vector<gpu::DrawItem> items;
  if (!object_ids.empty()) scene.appendDrawItems(object_ids, items);

  gpu::RenderTarget target(camera.width, camera.height);
  // Clear + draw, not Renderer::render: render() starts a GPU timer query, which cannot nest in the one a timed
  // frame has running when the runtime captures online (extract/pipeline_options.h). The readbacks wait for the GPU anyway.
  const auto pass = [&](gpu::RenderMode mode) {
    target.bind();
    target.clear(mode == gpu::RenderMode::ItemBuffer ? Vec4(0.0f, 0.0f, 0.0f, 1.0f) : renderer.light().sky_color);
    renderer.draw(camera, items, target, mode);
  };
  pass(gpu::RenderMode::Shaded);
  ImpostorCapture capture;
  capture.camera = camera;
  capture.color = target.readColor();
  capture.depth = target.readDepth();
  capture.ids = target.readIds();

  if (options.detect_seen_from_below && !items.empty()) {
    // Double-sided copies of the materials (one per distinct material, addresses kept stable by reserving).
    std::unordered_map<const gpu::GpuMaterial*, size_t> copy_of;
    std::vector<gpu::GpuMaterial> copies;
    copies.reserve(items.size());
    const gpu::GpuMaterial default_material;
    bool any_single_sided = false;
    for (gpu::DrawItem& item : items) {
      const gpu::GpuMaterial* original = item.material ? item.material : &default_material;
      const auto [it, inserted] = copy_of.emplace(original, copies.size());
      if (inserted) {
        copies.push_back(*original);
        any_single_sided |= !original->double_sided;
        copies.back().double_sided = true;
      }
      item.material = &copies[it->second];
    }
    if (any_single_sided) {
      // Depth only matters here: the item-buffer mode skips texturing, which is most of the cost in software.
      pass(gpu::RenderMode::ItemBuffer);
      const image::DepthImage both = target.readDepth();
      for (size_t i = 0; i < both.pixelCount(); ++i) {
        const float front = capture.depth.pixels()[i], any = both.pixels()[i];
        // Reversed Z: larger is nearer. The relative margin only absorbs rounding; equal surfaces give equal depth.
        if (any > front * (1.0f + 1e-5f) + 1e-9f) {
          capture.color.pixels()[i] = kSeenFromBelowColor;
          ++capture.seen_from_below_pixels;
        }
      }
    }
  }
  for (size_t i = 0; i < capture.color.pixelCount(); ++i)
    capture.data_pixels += isImpostorData(capture.color.pixels()[i], capture.depth.pixels()[i]) ? 1 : 0;
  capture.render_ms = timer.milliseconds();
  return capture;
}

ImpostorCapture captureView(const gpu::GpuScene& scene, std::span<const uint32_t> object_ids, const Camera& camera,
                            const CaptureOptions& options) {
  gpu::Renderer renderer;
  return captureView(renderer, scene, object_ids, camera, options);
}

}  // namespace farfield::impostor
