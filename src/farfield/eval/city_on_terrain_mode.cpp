// A city and a terrain in one frame (see city_on_terrain_mode.h).
#include "farfield/eval/city_on_terrain_mode.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <string>
#include <vector>
#include <utility>

#include "farfield/core/error.h"

namespace farfield::eval {
namespace {

// The terrain's depth bias under a city, in depth slopes per pixel: its LOD error is at most high_error (1 px).
constexpr float kDepthBiasSlopes = 2.0f;

// A city made on another terrain (or another scale, or none) would float above or sink into this one with nothing
// to show for it but wrong frames: the ground mesh's vertices (every k-th, up to about 1,000) must lie on the
// terrain, within a metre or 1 % of its relief at the median.
void checkGroundLiesOnTerrain(const scene::Scene& scene, const scene::Object& ground, const terrain::TerrainData& data,
                              const std::string& mode) {
  std::vector<float> offsets;
  for (const scene::Part& part : ground.parts) {
    const std::vector<Vec3>& positions = scene.meshes[part.mesh].positions;
    const size_t step = std::max<size_t>(1, positions.size() / 1000);
    for (size_t k = 0; k < positions.size(); k += step) {
      const Vec3 p = Vec3(ground.transform * Vec4(positions[k], 1.0f));
      const double x = double(p.x) + data.source_centre.x, y = double(p.y) + data.source_centre.y;
      if (x < 0.0 || y < 0.0 || x > data.hf.extentX() || y > data.hf.extentY()) continue;
      offsets.push_back(std::abs(p.z - data.hf.sample(x, y)));
    }
  }
  if (offsets.empty()) throw Error("mode " + mode, "the city's ground lies outside the terrain");
  std::nth_element(offsets.begin(), offsets.begin() + std::ptrdiff_t(offsets.size() / 2), offsets.end());
  const float median = offsets[offsets.size() / 2];
  const float tolerance = std::max(1.0f, 0.01f * (data.hf.maxHeight() - data.hf.minHeight()));
  if (median > tolerance) {
    char line[160];
    std::snprintf(line, sizeof line, "the city's ground is %.1f m from the terrain at the median (over %.1f m)",
                  double(median), double(tolerance));
    throw Error("mode " + mode, std::string(line) + ": make the city with gen city --terrain SPEC --terrain-scale S "
                                                    "and give the same terrain= and terrain_scale= here");
  }
}

}  // namespace

CityOnTerrainMode::CityOnTerrainMode(std::string terrain, std::string city)
    : terrain_(std::move(terrain)), city_(std::move(city)) {
  if (terrain_ != "high" && terrain_ != "high-gpu" && terrain_ != "lod-sprite" && terrain_ != "lod-sprite-gpu")
    throw Error("mode " + name(), "the terrain technique must be high, high-gpu, lod-sprite or lod-sprite-gpu");
}

void CityOnTerrainMode::prepare(const ModeContext& context) {
  if (!context.scene) throw Error("mode " + name(), "needs the city's scene");
  run_ = terrainRunFor(context, name());
  const terrain::TerrainData& data = *run_->data;
  offset_ = Vec3(float(data.source_centre.x), float(data.source_centre.y), 0.0f);
  // The hole: grid points strictly inside the city's ground rectangle, one cell in from its edge.
  hole_ = {};
  for (const scene::Object& o : context.scene->objects) {
    if (o.name != "ground") continue;
    checkGroundLiesOnTerrain(*context.scene, o, data, name());
    const Box3& b = o.world_bounds;
    const double cx = data.hf.cell_x, cy = data.hf.cell_y;
    hole_.x0 = std::max(0, int(std::ceil((double(b.lo.x) + data.source_centre.x) / cx)) + 1);
    hole_.y0 = std::max(0, int(std::ceil((double(b.lo.y) + data.source_centre.y) / cy)) + 1);
    hole_.x1 = std::min(data.hf.width - 1, int(std::floor((double(b.hi.x) + data.source_centre.x) / cx)) - 1);
    hole_.y1 = std::min(data.hf.height - 1, int(std::floor((double(b.hi.y) + data.source_centre.y) / cy)) - 1);
    break;
  }
  gpu::TerrainRenderer& renderer = run_->gpuRenderer();
  if (terrain_ == "high-gpu") run_->gpuLod();
  if (terrain_ == "lod-sprite" || terrain_ == "lod-sprite-gpu") {
    // LOD-sprite's per-frame choice needs this machine's terrain costs (terrain bench calibrates them on its path),
    // with the CDLOD terrain's frames for lod-sprite-gpu.
    terrain::GpuLodTerrain* gpu = terrain_ == "lod-sprite-gpu" ? &run_->gpuLod() : nullptr;
    if (!run_->cost || (gpu && !run_->cost->gpu_sprite)) {
      terrain::TerrainCostOptions c = calibrationViews(context);
      c.gpu_high = gpu;
      run_->cost = terrain::calibrateTerrainCost(*data.lod, renderer, c);
    }
    terrain::LodSpriteOptions o = spriteOptions(*run_, SpriteVariant::Paper, run_->epsilon, gpu);
    o.hole = hole_;
    sprite_ = std::make_unique<terrain::LodSpriteRenderer>(*data.lod, renderer, context.width, context.height, o);
  }
  city_mode_ = createMode(city_, context);
  city_mode_->prepare(context);
}

terrain::TerrainCostOptions CityOnTerrainMode::calibrationViews(const ModeContext& context) const {
  // Five views of the terrain around the city: from above each corner of the city's ground, looking out across the
  // terrain beyond it, and one from high above the centre.
  const terrain::TerrainData& data = *run_->data;
  const scene::Scene& scene = *context.scene;
  const Box3 b = scene.bounds();
  const Vec3 lo = b.lo + offset_, hi = b.hi + offset_;
  const Vec3 centre = 0.5f * (lo + hi);
  const float reach = std::max(hi.x - lo.x, hi.y - lo.y);
  std::vector<Camera> views;
  auto view = [&](Vec3 eye, Vec3 at) {
    Camera v;
    v.eye = eye;
    v.at = at;
    v.width = context.width;
    v.height = context.height;
    v.near_plane = 1.0f;
    v.far_plane = float(std::max(20000.0, 2.0 * std::max(data.hf.extentX(), data.hf.extentY())));
    views.push_back(v);
  };
  for (int k = 0; k < 4; ++k) {
    const Vec3 corner((k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, hi.z + 0.1f * reach);
    const Vec3 outward = glm::normalize(Vec3(corner.x - centre.x, corner.y - centre.y, 0.0f));
    view(corner, corner + outward * reach + Vec3(0.0f, 0.0f, -0.3f * reach));
  }
  view(Vec3(centre.x, centre.y - 0.01f * reach, hi.z + reach), Vec3(centre.x, centre.y, lo.z));
  return spriteCostOptions(*run_, std::move(views), context.width, context.height);
}

Camera CityOnTerrainMode::terrainCamera(const Camera& city_camera) const {
  Camera c = city_camera;
  c.eye += offset_;
  c.at += offset_;
  return c;
}

void CityOnTerrainMode::frame(FrameContext& frame) {
  // A path frame at or before the last one starts a new pass (as the sprite modes do).
  if (sprite_ && started_ && frame.pathFrame() <= last_frame_) sprite_->reset();
  started_ = true;
  last_frame_ = frame.pathFrame();
  gpu::RenderTarget& target = frame.beginOwnPass();
  const Camera camera = terrainCamera(frame.camera());
  gpu::FrameStats stats;
  gpu::TerrainRenderer& renderer = run_->gpuRenderer();
  // Where the terrain's LOD triangles reach over the city's ground near the hole's edge, the ground wins.
  renderer.setDepthBias(kDepthBiasSlopes, kDepthBiasSlopes);
  if (sprite_) {
    terrain::GpuLodTerrain* gpu = sprite_->options().gpu_high;
    if (gpu) gpu->renderer().setDepthBias(kDepthBiasSlopes, kDepthBiasSlopes);
    terrain::LodSpriteFrameInfo info;
    stats = sprite_->render(camera, target, &info);
    last_sprite_frame_ = info.frame;
    if (gpu) gpu->renderer().setDepthBias(0.0f, 0.0f);
  } else if (terrain_ == "high-gpu") {
    terrain::GpuLodTerrain& lod = run_->gpuLod();
    lod.setHole(hole_);  // the quadtree's hole, left out by the fragment shader
    lod.renderer().setDepthBias(kDepthBiasSlopes, kDepthBiasSlopes);
    stats = lod.draw(camera, run_->high_error, target).draw;
    lod.renderer().setDepthBias(0.0f, 0.0f);
    lod.clearHole();
  } else {
    stats = terrain::renderLodFrame(*run_->data->lod, renderer, camera,
                                    terrain::LodSettings{run_->high_error, true, false}, target, mesh_, hole_);
  }
  renderer.setDepthBias(0.0f, 0.0f);
  terrain_triangles_ += stats.triangles;
  ++frames_;
  frame.addStats(stats);
  city_mode_->frame(frame);
}

void CityOnTerrainMode::frameMeasured(size_t path_frame, double wall_ms) {
  city_mode_->frameMeasured(path_frame, wall_ms);
  if (sprite_ && run_->cost_correction) sprite_->measured(last_sprite_frame_, wall_ms);
}

std::map<std::string, double> CityOnTerrainMode::info() const {
  std::map<std::string, double> out;
  for (const auto& [key, value] : city_mode_->info()) out["city_" + key] = value;
  out["terrain_triangles_per_frame"] = frames_ ? double(terrain_triangles_) / double(frames_) : 0.0;
  out["terrain_hole_grid_points"] =
      hole_.empty() ? 0.0 : double(hole_.x1 - hole_.x0 + 1) * double(hole_.y1 - hole_.y0 + 1);
  if (sprite_) {
    const terrain::LodSpriteCounters& c = sprite_->counters();
    out["terrain_keyframes"] = double(c.fresh_keyframes);
    out["terrain_keyframe_fraction"] = double(c.fresh_keyframes) / double(std::max<size_t>(c.frames, 1));
    out["terrain_epsilon_px"] = sprite_->options().epsilon;
    out["terrain_high_frames"] = double(c.high_frames);
    out["terrain_virtual_keyframes"] = double(c.virtual_keyframes);
    out["terrain_switches"] = double(c.switches);
    const terrain::CostCorrection& k = sprite_->costCorrection();
    out["terrain_correction_high"] = k.factor(terrain::TerrainFrameKind::High);
    out["terrain_correction_sprite"] = k.factor(terrain::TerrainFrameKind::Sprite);
    out["terrain_correction_measurements"] = double(k.measurementsUsed());
  }
  return out;
}

void registerCityOnTerrainModes() {
  for (const char* terrain : {"high", "high-gpu", "lod-sprite", "lod-sprite-gpu"})
    for (const char* city : {"culled", "dynamic-shade"}) {
      const std::string t = terrain, c = city;
      registerMode("terrain-" + t + "+" + c,
                   "a city (" + c + ") on a terrain (" + t +
                       ") in one frame (--mode-option terrain=SPEC terrain_scale=S, as gen city --terrain)",
                   [t, c](const ModeContext&) { return std::make_unique<CityOnTerrainMode>(t, c); });
    }
}

}  // namespace farfield::eval
