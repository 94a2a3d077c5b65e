// Bench modes for billboards and the hierarchical image cache with Shade's or Schaufler's metric
// (steed-ibr-impostors-lecture, part 2, "billboard", "First metric - Shade", "Second metric - Schaufler").
#include "farfield/eval/dynamic_modes.h"

#include <algorithm>

#include "farfield/core/error.h"
#include "farfield/core/error_bound.h"
#include "farfield/core/timer.h"
#include "farfield/eval/layered_calibration.h"
#include "farfield/eval/mode_options.h"
#include "farfield/eval/occlusion_pass.h"
#include "farfield/gpu/cost_model.h"
#include "farfield/gpu/cost_profile.h"
#include "farfield/impostor/capture.h"
#include "farfield/scene/mesh.h"

namespace farfield::eval {

void registerDynamicModes() {
  registerMode("billboard",
               "the scene's trees (objects named tree) as billboards (8 captured views, cylindrical) where their "
               "closed-form error keeps the bound (--mode-option error_px), geometry elsewhere; culled geometry",
               [](const ModeContext& c) { return std::make_unique<BillboardMode>(c); });
  registerMode("dynamic-shade",
               "hierarchical image cache (Shade 1996): planar images on their best plane, regenerated when Shade's "
               "angle over box corners exceeds the bound, inside t_max (--mode-option t_max_ms)",
               [](const ModeContext& c) {
                 return std::make_unique<DynamicImpostorMode>(impostor::ValidityMetric::Shade, c);
               });
  registerMode("dynamic-schaufler",
               "hierarchical image cache, regenerated when Schaufler's translation or size angle exceeds the bound",
               [](const ModeContext& c) {
                 return std::make_unique<DynamicImpostorMode>(impostor::ValidityMetric::Schaufler, c);
               });
  registerMode("layered",
               "hierarchical image cache of layered impostors (impostor/layered.h, depth slices by alpha test), each "
               "planned for a shaft around the eye it was captured from and regenerated when the eye leaves it",
               [](const ModeContext& c) {
                 return std::make_unique<DynamicImpostorMode>(impostor::ValidityMetric::Schaufler, c,
                                                              runtime::CachedImageKind::Layered);
               });
  registerMode("warp",
               "post-render warping: culled-geometry keyframes every warp_interval frames, frames between warped "
               "from the latest keyframe with holes filled from the one before (3D warping using depth)",
               [](const ModeContext& c) { return std::make_unique<WarpMode>(c); });
}

// ---- billboard ----

BillboardMode::BillboardMode(const ModeContext& context) {
  error_px_ = numberOption(context, "error_px", 2.0, 0.01);
  options_.kind = choiceOption(context, "billboard_kind", "cylindrical", {"cylindrical", "spherical"}) == "spherical"
                      ? impostor::BillboardKind::Spherical
                      : impostor::BillboardKind::Cylindrical;
  options_.views = intOption(context, "billboard_views", 8, 1, 64);
  options_.texels = intOption(context, "billboard_texels", 32, 4, 2048);
  options_.elevation = options_.kind == impostor::BillboardKind::Spherical ? 0.15 : 0.0;
  geometry_draw_.emplace(context, name());
}

void BillboardMode::prepare(const ModeContext& context) {
  Stopwatch clock;
  gpu_scene_ = context.gpu_scene;
  bvh_ = context.bvh;
  geometry_draw_->prepare(context);
  const scene::Scene& scene = *context.scene;
  tree_of_object_.assign(scene.objects.size() + 1, 0);
  std::vector<impostor::Billboard> boards;
  for (const scene::Object& o : scene.objects) {
    if (o.name != "tree" || o.world_bounds.empty()) continue;
    const uint32_t ids[] = {o.id};
    boards.push_back(impostor::captureBillboard(*context.renderer, *context.gpu_scene, ids, o.world_bounds, options_));
    tree_ids_.push_back(o.id);
    tree_of_object_[o.id] = uint32_t(boards.size());
  }
  if (boards.empty())
    throw Error("mode 'billboard'", "the scene has no objects named 'tree' (farfield gen city --trees, gen forest)");
  batch_ = std::make_unique<impostor::BillboardBatch>(boards);
  prepare_s_ = clock.seconds();
}

void BillboardMode::frame(FrameContext& frame) {
  const Camera& cam = frame.camera();
  const double theta = ErrorBound::forCamera(error_px_, cam).angle();
  visible_.clear();
  bvh_->queryFrustum(Frustum::fromMatrix(cam.viewProjection()), visible_);
  std::sort(visible_.begin(), visible_.end());
  geometry_.clear();
  boards_.clear();
  for (const uint32_t id : visible_) {
    const uint32_t b = tree_of_object_[id];
    if (b && batch_->shape(b - 1).errorAngle(cam.eye) <= theta) boards_.push_back(b - 1);
    else geometry_.push_back(id);
  }
  geometry_draw_->submitObjects(frame, geometry_);
  const size_t bytes = boards_.empty() ? 0 : batch_->build(boards_, cam.eye, frame.items());
  ++frames_;
  billboards_drawn_ += boards_.size();
  trees_as_geometry_ += geometry_.size();
  uploaded_bytes_ += bytes;
}

std::map<std::string, double> BillboardMode::info() const {
  const double f = double(std::max<size_t>(frames_, 1));
  std::map<std::string, double> out = geometry_draw_->info();
  out.merge(std::map<std::string, double>{{"error_bound_px", error_px_},
          {"billboards", double(tree_ids_.size())},
          {"views", double(options_.views)},
          {"texels", double(options_.texels)},
          {"texture_bytes", double(batch_ ? batch_->textureBytes() : 0)},
          {"billboards_per_frame", double(billboards_drawn_) / f},
          {"geometry_objects_per_frame", double(trees_as_geometry_) / f},
          {"uploaded_bytes_per_frame", double(uploaded_bytes_) / f},
          {"regenerations_per_frame", 0.0},
          {"prepare_s", prepare_s_}});
  return out;
}

// ---- dynamic-shade / dynamic-schaufler ----

DynamicImpostorMode::DynamicImpostorMode(impostor::ValidityMetric metric, const ModeContext& context,
                                         runtime::CachedImageKind kind) {
  options_.kind = kind;
  options_.metric = metric;
  options_.error_px = numberOption(context, "error_px", 2.0, 0.01);
  options_.t_max_ms = numberOption(context, "t_max_ms", 0.0, 0.0);
  options_.max_regenerations = intOption(context, "max_regenerations", 32, 0, 100000);
  options_.lost_frame_investment = numberOption(context, "lost_frame_investment", 1.0, 0.0);
  options_.audit_samples = intOption(context, "audit", 0, 0, 1000000);
  options_.pay_back = switchOption(context, "pay_back", true);
  options_.impostor.plane_in_front = choiceOption(context, "plane", "best", {"best", "front"}) == "front";
  profile_path_ = context.option("profile");
  if (choiceOption(context, "geometry", "gpu", {"gpu", "cpu"}) == "gpu") {
    geometry_draw_.emplace(context, name());  // its own occlusion option: the GPU culler's test
  } else if (switchOption(context, "occlusion", true)) {
    occlusion_.emplace();
    occlusion_->occluder_share = occluderShareOption(context, name());
  }
}

std::string DynamicImpostorMode::name() const {
  if (options_.kind == runtime::CachedImageKind::Layered) return "layered";
  return std::string("dynamic-") + impostor::validityMetricName(options_.metric);
}

void DynamicImpostorMode::prepare(const ModeContext& context) {
  scene_ = context.scene;
  gpu_scene_ = context.gpu_scene;
  Stopwatch clock;
  if (!profile_path_.empty()) {
    // The machine's validated profile (farfield calibrate on this scene's view space): its model, its safety factor
    // and its layered terms.
    const gpu::CostProfile profile = gpu::loadCostProfile(profile_path_);
    options_.cost = profile.model;
    options_.cost_safety_factor = profile.safety_factor;
    options_.layered_cost = profile.layered;
  } else {
    gpu::CalibrationOptions calibration;
    calibration.repeats = 1;
    calibration.sizes = {256, 512};
    calibration.max_triangles = 200000;
    options_.cost = gpu::calibrateCostModel(*context.renderer, *context.gpu_scene, calibration);
    if (options_.kind == runtime::CachedImageKind::Layered) {
      // A quick fit of the layered draw and capture terms on the scene's clusters seen from anywhere in its bounds.
      LayeredCalibrateOptions lo;
      lo.width = context.width;
      lo.height = context.height;
      lo.error_px = options_.error_px;
      lo.view_space = context.scene->bounds();
      lo.fit_samples = 12;
      lo.validation_samples = 8;
      lo.repeats = 1;
      lo.layered.max_texture_size = options_.impostor.max_texels;
      lo.layered.max_layers = 16;
      options_.layered_cost = calibrateLayered(*context.renderer, *context.gpu_scene, *context.scene, lo).cost;
    }
  }
  calibrate_s_ = clock.seconds();
  cache_ = std::make_unique<runtime::ImageCache>(*context.scene, *context.gpu_scene, options_);
  if (geometry_draw_) geometry_draw_->prepare(context);
}

void DynamicImpostorMode::frame(FrameContext& frame) {
  gpu::RenderTarget& target = frame.beginOwnPass();
  if (geometry_draw_) {
    // Regenerations first (into their own targets), then the geometry through the GPU culler, then the images.
    geometry_objects_.clear();
    per_frame_[frame.pathFrame()] = cache_->frame(frame.renderer(), frame.camera(), frame.pathFrame(), frame.items(),
                                                  nullptr, &geometry_objects_);
    std::sort(geometry_objects_.begin(), geometry_objects_.end());
    geometry_objects_.erase(std::unique(geometry_objects_.begin(), geometry_objects_.end()), geometry_objects_.end());
    geometry_draw_->submitObjects(frame, geometry_objects_);
    return;
  }
  if (occlusion_) {
    occlusion_->target = &target;
    occlusion_->draw_occluders = [&frame](std::span<const gpu::DrawItem> items) { frame.drawPass(items); };
  }
  per_frame_[frame.pathFrame()] = cache_->frame(frame.renderer(), frame.camera(), frame.pathFrame(), frame.items(),
                                                occlusion_ ? &*occlusion_ : nullptr);
}

std::map<std::string, double> DynamicImpostorMode::info() const {
  double regen = 0, regen_max = 0, images = 0, geometry = 0, written = 0, uploaded = 0, tex_max = 0, audited = 0,
         unneeded = 0, missed = 0, frames_with_regen = 0, predicted = 0, deferred = 0, frames_with_deferred = 0;
  double lost = 0, lost_with_regen = 0, hidden_nodes = 0, hidden_node_tris = 0, hidden_items = 0, hidden_tris = 0,
         occluders = 0, occlusion_ms = 0, hidden_fallback_tris = 0;
  for (const auto& [k, s] : per_frame_) {
    regen += double(s.regenerations);
    regen_max = std::max(regen_max, double(s.regenerations));
    frames_with_regen += s.regenerations > 0;
    images += double(s.images_drawn);
    geometry += double(s.geometry_nodes);
    written += double(s.texels_written_bytes);
    uploaded += double(s.uploaded_bytes);
    tex_max = std::max(tex_max, double(s.texture_bytes));
    audited += double(s.audited);
    unneeded += double(s.unneeded);
    missed += double(s.missed);
    predicted += s.predicted_ms;
    deferred += double(s.geometry_nodes);
    frames_with_deferred += s.geometry_nodes > 0;
    lost += double(s.lost);
    lost_with_regen += double(s.lost && s.regenerations > 0);
    hidden_nodes += double(s.hidden_nodes);
    hidden_node_tris += double(s.hidden_node_triangles);
    hidden_items += double(s.hidden_items);
    hidden_tris += double(s.hidden_triangles);
    occluders += double(s.occluders);
    occlusion_ms += s.occlusion_ms;
    hidden_fallback_tris += double(s.hidden_fallback_triangles);
  }
  const double f = double(std::max<size_t>(per_frame_.size(), 1));
  // geometry_gpu and the GPU culler's numbers (gpu_*), or geometry_gpu 0 and the CPU occlusion's below.
  std::map<std::string, double> out =
      geometry_draw_ ? geometry_draw_->info() : std::map<std::string, double>{{"geometry_gpu", 0.0}};
  // Which path frames regenerated (to check their measured times against t_max): "regenerations_at_frame_K", for at
  // most 500 such frames.
  size_t listed = 0;
  for (const auto& [k, s] : per_frame_)
    if (s.regenerations > 0 && listed++ < 500) out["regenerations_at_frame_" + std::to_string(k)] = double(s.regenerations);
  out.merge(std::map<std::string, double>{{"error_bound_px", options_.error_px},
          {"t_max_ms", options_.t_max_ms},
          {"predicted_ms_mean", predicted / f},
          {"nodes", double(cache_ ? cache_->nodeCount() : 0)},
          {"regenerations_per_frame", regen / f},
          {"regenerations_max", regen_max},
          {"frames_with_regenerations", frames_with_regen},
          {"images_per_frame", images / f},
          {"invalid_as_geometry_per_frame", geometry / f},
          {"texels_written_bytes_per_frame", written / f},
          {"uploaded_bytes_per_frame", uploaded / f},
          {"texture_bytes_max", tex_max},
          {"audited", audited},
          {"unneeded_regenerations", unneeded},
          {"missed_regenerations", missed},
          {"calibrate_s", calibrate_s_},
          {"cost_safety_factor", options_.cost_safety_factor},
          {"layered_cost_calibrated", options_.layered_cost.calibrated ? 1.0 : 0.0},
          {"deferred_regenerations_per_frame", deferred / f},
          {"frames_with_deferred", frames_with_deferred},
          {"lost_frame_investment", options_.lost_frame_investment},
          {"frames_predicted_lost", lost},
          {"frames_predicted_lost_with_regenerations", lost_with_regen},
          {"occlusion", occlusion_ ? 1.0 : 0.0},
          {"occlusion_hidden_nodes_per_frame", hidden_nodes / f},
          {"occlusion_hidden_node_triangles_per_frame", hidden_node_tris / f},
          {"occlusion_hidden_items_per_frame", hidden_items / f},
          {"occlusion_hidden_triangles_per_frame", hidden_tris / f},
          {"occlusion_occluder_items_per_frame", occluders / f},
          {"occlusion_hidden_fallback_triangles_per_frame", hidden_fallback_tris / f},
          {"occlusion_ms_per_frame", occlusion_ms / f}});
  return out;
}

}  // namespace farfield::eval

namespace farfield::eval {

// ---- warp ----

WarpMode::WarpMode(const ModeContext& context) {
  interval_ = countOption(context, "warp_interval", 4, 1, 1000);
}

void WarpMode::prepare(const ModeContext& context) {
  gpu_scene_ = context.gpu_scene;
  bvh_ = context.bvh;
  texture_ = std::make_unique<gpu::Texture>(context.width, context.height, gpu::TextureFormat::Rgba8);
  texture_->setClampToEdge();
  material_ = std::make_unique<gpu::GpuMaterial>();
  material_->texture = texture_.get();
  material_->unlit = true;
  material_->double_sided = true;
}

void WarpMode::drawScreenQuad(FrameContext& frame, const image::ColorImage& image) {
  texture_->upload(image);
  const Camera& cam = frame.camera();
  // A quad just beyond the near plane covering the view exactly: pixel (x, y) of the image lands on pixel (x, y).
  const Vec3 f = cam.forward();
  const Vec3 r = glm::normalize(glm::cross(f, cam.up)), u = glm::cross(r, f);
  const float d = cam.near_plane * 1.5f, t = std::tan(0.5f * cam.fov_y) * d, s = t * cam.aspect();
  const Vec3 c = cam.eye + d * f;
  scene::Mesh m;
  m.positions = {c - s * r - t * u, c + s * r - t * u, c + s * r + t * u, c - s * r + t * u};
  m.normals.assign(4, -f);
  m.uvs = {Vec2(0, 1), Vec2(1, 1), Vec2(1, 0), Vec2(0, 0)};
  m.indices = {0, 1, 2, 0, 2, 3};
  m.computeBounds();
  quad_ = gpu::GpuMesh(m);
  gpu::DrawItem item;
  item.mesh = &quad_;
  item.material = material_.get();
  frame.items().push_back(item);
}

void WarpMode::frame(FrameContext& frame) {
  const size_t k = frame.pathFrame();
  const Camera& cam = frame.camera();
  gpu::RenderTarget& target = frame.beginOwnPass();
  const bool repeat_of_key = !keys_.empty() && keys_.back().path_frame == k;
  const bool new_pass = !keys_.empty() && k < keys_.back().path_frame;
  if (new_pass) keys_.clear();
  if (keys_.empty() || repeat_of_key || k - keys_.back().path_frame >= interval_) {
    ids_.clear();
    bvh_->queryFrustum(Frustum::fromMatrix(cam.viewProjection()), ids_);
    std::sort(ids_.begin(), ids_.end());
    std::vector<gpu::DrawItem> items;
    if (!ids_.empty()) gpu_scene_->appendDrawItems(ids_, items, cam);
    frame.drawPass(items);
    Keyframe key{target.readColor(), target.readDepth(), cam, k};
    if (repeat_of_key) keys_.back() = std::move(key);
    else keys_.push_back(std::move(key));
    if (keys_.size() > 2) keys_.erase(keys_.begin());
    per_frame_[k] = {1.0, double(cam.width) * cam.height * 8.0, 0.0, 0.0};
    return;
  }
  const Keyframe& latest = keys_.back();
  const impostor::DepthView primary{&latest.color, &latest.depth, latest.camera};
  impostor::WarpedImage w = keys_.size() > 1
                                ? impostor::warpWithHoleFilling(
                                      primary, {&keys_.front().color, &keys_.front().depth, keys_.front().camera}, cam)
                                : impostor::warpDepthImage(primary, cam);
  size_t holes = 0;
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) holes += w.source.at(x, y) == 0;
  drawScreenQuad(frame, w.color);
  per_frame_[k] = {0.0, 0.0, double(cam.width) * cam.height * 4.0 + double(quad_.byteSize()), double(holes)};
}

std::map<std::string, double> WarpMode::info() const {
  double keys = 0, read = 0, up = 0, empty = 0;
  for (const auto& [k, v] : per_frame_) {
    keys += v[0];
    read += v[1];
    up += v[2];
    empty += v[3];
  }
  const double f = double(std::max<size_t>(per_frame_.size(), 1));
  return {{"warp_interval", double(interval_)},
          {"keyframes_per_frame", keys / f},
          {"regenerations_per_frame", keys / f},
          {"readback_bytes_per_frame", read / f},
          {"uploaded_bytes_per_frame", up / f},
          {"empty_pixels_per_warped_frame", empty / std::max(1.0, f - keys)},  // holes left and sky
          {"texture_bytes", double(texture_ ? texture_->byteSize() : 0)}};
}

}  // namespace farfield::eval
