// Frame-time cost model of LOD-sprite terrain (Chen et al. 1999 section 3), fitted on the running machine.
#include "farfield/terrain/terrain_cost.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "farfield/core/check.h"
#include "farfield/core/error.h"
#include "farfield/core/timer.h"
#include "farfield/gpu/render_target.h"

namespace farfield::terrain {

double TerrainCost::frameMs(double triangles, double draw_calls, int width, int height) const {
  return frame.predict(triangles, draw_calls, double(width) * double(height)) * safety_factor;
}

double TerrainCost::gpuHighMs(double triangles, int width, int height) const {
  FF_CHECK_MSG(gpu_high.has_value(), "no CDLOD frame model was fitted");
  return gpu_high->predict(triangles, 1.0, double(width) * double(height)) * safety_factor;
}

double TerrainCost::gpuSpriteMs(double triangles, int width, int height) const {
  FF_CHECK_MSG(gpu_sprite.has_value(), "no CDLOD sprite frame model was fitted");
  return gpu_sprite->predict(triangles, 1.0, double(width) * double(height)) * safety_factor;
}

double TerrainCost::readbackMs(int width, int height) const {
  return readback_ms_per_mpixel * double(width) * double(height) * 1e-6 * safety_factor;
}

nlohmann::json TerrainCost::toJson() const {
  nlohmann::json j = {{"frame", frame.toJson()},
                      {"readback_ms_per_mpixel", readback_ms_per_mpixel},
                      {"safety_factor", safety_factor}};
  if (gpu_high) j["gpu_high"] = gpu_high->toJson();
  if (gpu_sprite) j["gpu_sprite"] = gpu_sprite->toJson();
  return j;
}

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// Checks the options; the frame's and the keyframe's sizes.
void checkOptions(const TerrainCostOptions& options, bool sprite_calls, IVec2& frame, IVec2& keyframe) {
  const char* where = "terrain cost calibration";
  if (options.views.empty()) throw Error(where, "needs at least one view");
  if (options.repeats < 1) throw Error(where, "repeats must be at least 1");
  if (options.pixel_errors.empty()) throw Error(where, "no LOD thresholds to time");
  for (float e : options.pixel_errors)
    if (!(e > 0.0f)) throw Error(where, "LOD thresholds must be positive (pixels)");
  if (sprite_calls) {
    if (options.sprite_calls.empty()) throw Error(where, "no draw-call counts to time");
    for (int c : options.sprite_calls)
      if (c < 0 || c > 256) throw Error(where, "sprite draw calls must be 0..256 (0: the original texture alone)");
  }
  for (const Camera& v : options.views) v.validate(where);
  frame = IVec2(options.views.front().width, options.views.front().height);
  keyframe = IVec2(options.keyframe_width > 0 ? options.keyframe_width : frame.x,
                   options.keyframe_height > 0 ? options.keyframe_height : frame.y);
}

const Vec4 kSky{0.6f, 0.7f, 0.9f, 1.0f};

// The CDLOD frames of one view at each threshold (gpu_high) and its sprite frames with the view's keyframe at the
// finest threshold as the sprite (gpu_sprite), into `target` (`sprite` holds the keyframe); one untimed warm-up draw
// first of each (llvmpipe compiles a program at its first draw).
void timeCdlodView(GpuLodTerrain& terrain, const Camera& camera, const TerrainCostOptions& options,
                   gpu::RenderTarget& target, gpu::RenderTarget& sprite, std::vector<gpu::CostSample>& high,
                   std::vector<gpu::CostSample>& sprite_frames) {
  const double pixels = double(target.width()) * double(target.height());
  auto timeCdlod = [&](std::vector<gpu::CostSample>& out) {
    target.clear(kSky);
    terrain.draw(camera, options.pixel_errors.front(), target);
    terrain.renderer().finish();
    for (const float tau : options.pixel_errors) {
      std::vector<double> times;
      double triangles = 0.0;
      for (int r = 0; r < options.repeats; ++r) {
        Stopwatch clock;
        target.clear(kSky);
        triangles = double(terrain.draw(camera, tau, target).draw.triangles);
        terrain.renderer().finish();
        times.push_back(clock.milliseconds());
      }
      out.push_back({triangles, 1.0, pixels, median(times)});
    }
  };
  timeCdlod(high);
  sprite.clear(kSky);
  terrain.draw(camera, options.pixel_errors.front(), sprite);
  gpu::CdlodSprite key;
  key.colour = &sprite.colorTexture();
  key.depth = &sprite.depthTexture();
  key.camera = camera;
  terrain.renderer().setSprite(key);
  timeCdlod(sprite_frames);
  terrain.renderer().clearSprite();
  sprite.clear(kSky);
}

}  // namespace

TerrainCost calibrateTerrainCost(const QuadtreeLod& lod, gpu::TerrainRenderer& renderer,
                                 const TerrainCostOptions& options) {
  IVec2 frame, keyframe;
  checkOptions(options, true, frame, keyframe);
  const int fw = frame.x, fh = frame.y, kw = keyframe.x, kh = keyframe.y;

  std::vector<gpu::CostSample> samples, gpu_samples, sprite_samples;
  std::vector<double> readback_ms;
  LodMesh mesh;
  for (const int size : {0, 1}) {
    const int w = size ? kw : fw, h = size ? kh : fh;
    gpu::RenderTarget target(w, h), sprite(w, h);
    sprite.clear(kSky);
    for (const Camera& view : options.views) {
      // The keyframe target is wider at the same pixel density (lod_sprite.h's guard band).
      const Camera camera = view.resized(w, h);
      const Mat4 sprite_view_proj = camera.viewProjection();
      // Warm-up (untimed): first use of this target, of both programs (llvmpipe compiles a shader variant at its first
      // draw) and the densest mesh.
      lod.build(camera, LodSettings{options.pixel_errors.front(), true, false}, mesh);
      renderer.setIndices(mesh.indices, 0);
      target.clear(kSky);
      renderer.drawTextured(camera, target, 0, mesh.triangleCount(), 0);
      renderer.drawSprite(camera, target, sprite.colorTexture(), sprite_view_proj, 0, mesh.triangleCount(), 0);
      renderer.finish();
      // Each mesh drawn with the original texture in one call, and as a sprite frame: half the triangles with the
      // sprite, in sprite_calls calls (a frame with sprites per tile draws one a tile), the rest in one call.
      for (const float tau : options.pixel_errors)
        for (const int sprite_calls : options.sprite_calls) {
          const bool with_sprite = sprite_calls > 0;
          std::vector<double> times;
          double triangles = 0.0;
          for (int r = 0; r < options.repeats; ++r) {
            Stopwatch clock;
            target.clear(kSky);
            lod.build(camera, LodSettings{tau, true, with_sprite}, mesh);
            renderer.setIndices(mesh.indices, 0);
            const size_t n = mesh.triangleCount();
            if (with_sprite) {
              const size_t calls = size_t(sprite_calls);
              for (size_t c = 0; c < calls; ++c) {
                const size_t first = n / 2 * c / calls, last = n / 2 * (c + 1) / calls;
                renderer.drawSprite(camera, target, sprite.colorTexture(), sprite_view_proj, first, last - first, 0);
              }
              renderer.drawTextured(camera, target, n / 2, n - n / 2, 0);
            } else {
              renderer.drawTextured(camera, target, 0, n, 0);
            }
            renderer.finish();
            times.push_back(clock.milliseconds());
            triangles = double(n);
          }
          samples.push_back({triangles, double(sprite_calls + 1), double(w) * double(h), median(times)});
        }
      if (options.gpu_high)
        timeCdlodView(*options.gpu_high, camera, options, target, sprite, gpu_samples, sprite_samples);
      if (size) {
        for (int r = 0; r < options.repeats; ++r) {
          Stopwatch clock;
          const image::DepthImage depth = target.readDepth();
          readback_ms.push_back(clock.milliseconds());
        }
      }
    }
  }
  TerrainCost cost;
  cost.frame = gpu::CostModel::fit(samples);
  if (!gpu_samples.empty()) cost.gpu_high = gpu::CostModel::fit(gpu_samples);
  if (!sprite_samples.empty()) cost.gpu_sprite = gpu::CostModel::fit(sprite_samples);
  cost.readback_ms_per_mpixel = median(readback_ms) / (double(kw) * double(kh) * 1e-6);
  return cost;
}

TerrainCost calibrateCdlodCost(GpuLodTerrain& terrain, const TerrainCostOptions& options) {
  IVec2 frame, keyframe;
  checkOptions(options, false, frame, keyframe);
  std::vector<gpu::CostSample> high, sprite_frames;
  for (const IVec2 size : {frame, keyframe}) {
    gpu::RenderTarget target(size.x, size.y), sprite(size.x, size.y);
    for (const Camera& view : options.views)
      timeCdlodView(terrain, view.resized(size.x, size.y), options, target, sprite, high, sprite_frames);
  }
  TerrainCost cost;
  cost.gpu_high = gpu::CostModel::fit(high);
  cost.gpu_sprite = gpu::CostModel::fit(sprite_frames);
  return cost;
}

}  // namespace farfield::terrain
