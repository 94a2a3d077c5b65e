#include "farfield/runtime/crowd_runtime.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>

#include "farfield/core/error.h"
#include "farfield/core/timer.h"

namespace farfield::runtime {

namespace {


// Agent space -> world for an agent at `position` with `heading` (a turn about +z).
Vec3 turn(float heading, const Vec3& v) {
  const float c = std::cos(heading), s = std::sin(heading);
  return Vec3(c * v.x - s * v.y, s * v.x + c * v.y, v.z);
}

}  // namespace

double CrowdRuntime::focalOf(const Camera& camera) {
  return double(camera.height) / (2.0 * std::tan(double(camera.fov_y) / 2.0));
}

CrowdRuntime::CrowdRuntime(std::span<const scene::SkinnedModel> models,
                           std::span<const CrowdModelOptions> model_options, const CrowdRuntimeOptions& options)
    : options_(options) {
  if (models.size() != model_options.size()) throw Error("crowd runtime", "one option set per model");
  if (options.palette_poses < 1 ||
      (!options.atlas_from_bound && (options.frames < 1 || options.palette_poses % options.frames != 0)))
    throw Error("crowd runtime", "palette poses must be a positive multiple of the impostor frames");
  if (options.atlas_from_bound && (!(options.bound_switch_m > 0.0) || !(options.bound_focal_px > 0.0)))
    throw Error("crowd runtime", "the bound's switch distance and focal length must be positive");
  if (!(options.geometry_lod_px >= 0.0) || !std::isfinite(options.geometry_lod_px))
    throw Error("crowd runtime", "the geometry's level-of-detail bound must be a finite number of pixels >= 0");
  if (!(options.geometry_ms >= 0.0) || !std::isfinite(options.geometry_ms))
    throw Error("crowd runtime", "the geometry budget must be a finite number of milliseconds >= 0");
  if (!options.region_tints.empty()) renderer_.setRegionTints(options.region_tints);
  for (size_t m = 0; m < models.size(); ++m) {
    const scene::SkinnedModel& sm = models[m];
    const int a = sm.findAnimation(model_options[m].animation);
    if (a < 0) throw Error(sm.name, "no animation for a crowd");
    const scene::Animation& anim = sm.animations[size_t(a)];
    Model model;
    model.cycle_s = std::max(anim.duration, 1e-3f);
    std::vector<std::vector<Mat4>> poses;
    for (int p = 0; p < options.palette_poses; ++p)
      poses.push_back(scene::jointMatrices(sm, &anim, anim.start + anim.duration * float(p) / float(options.palette_poses)));
    // Agent space: the front turned to +x, scaled to the height, feet on z = 0, centred on the vertical axis.
    const Mat4 facing = glm::rotate(Mat4(1.0f), float(degToRad(model_options[m].facing_deg)), Vec3(0, 0, 1));
    Box3 raw;
    for (int p = 0; p < options.palette_poses; p += std::max(1, options.palette_poses / 8))
      for (const Vec3& v : scene::skinMesh(sm, poses[size_t(p)]).positions) raw.expand(Vec3(facing * Vec4(v, 1.0f)));
    const float height = raw.hi.z - raw.lo.z;
    if (!(height > 0.0f)) throw Error(sm.name, "the animated model has no height");
    const float s = model_options[m].height_m / height;
    const Vec3 c = raw.center();
    const Mat4 to_agent = glm::scale(Mat4(1.0f), Vec3(s)) * glm::translate(Mat4(1.0f), Vec3(-c.x, -c.y, -raw.lo.z)) * facing;
    Box3 agent_bounds;
    std::vector<std::vector<Vec3>> pose_positions(poses.size());
    for (size_t p = 0; p < poses.size(); ++p)
      for (const Vec3& v : scene::skinMesh(sm, poses[p]).positions) {
        pose_positions[p].push_back(Vec3(to_agent * Vec4(v, 1.0f)));
        agent_bounds.expand(pose_positions[p].back());
      }
    std::vector<scene::DeformingLevel> levels;
    if (options.geometry_lod_px > 0.0) {
      const Stopwatch timer;
      scene::DeformingLodOptions lod;
      lod.triangle_ratios = options.lod_ratios;
      // The colour regions are not passed as groups: holding their borders measured worse on the crowd bench
      // (docs/BENCHMARKS.md, Crowds: skinned levels of detail).
      levels = scene::deformingLevels(sm.mesh.indices, pose_positions, lod, sm.name, {}, sm.mesh.uvs);
      for (const scene::DeformingLevel& l : levels) {
        model.level_m.push_back(options.lod_texture ? std::max(l.error, l.texture_error) : l.error);
        model.level_surface_m.push_back(l.error);
        model.level_texture_m.push_back(l.texture_error);
      }
      lod_seconds_ += timer.seconds();
    }
    model.gpu = std::make_unique<gpu::SkinnedGpuModel>(sm, to_agent, poses, levels, options.skinning);
    model.centre = agent_bounds.center();
    model.radius = glm::length(agent_bounds.hi - model.centre);
    CrowdAtlasChoice& choice = model.choice;
    if (options.atlas_from_bound) {
      const Vec3 half = agent_bounds.hi - model.centre;
      const impostor::BoundChoice bc = impostor::chooseForBound(options.error_px, options.bound_focal_px,
                                                                options.bound_switch_m, std::hypot(half.x, half.y),
                                                                float(kPi / 2), options.grid.octahedral);
      choice.grid = bc.grid;
      choice.texel_m = bc.texel_m;
      choice.frames = impostor::framesForBound(pose_positions,
                                               options.error_px * options.bound_switch_m / options.bound_focal_px);
      choice.from_bound = true;
    } else {
      choice.grid = options.grid;
      choice.texel_m = options.texel_m;
      choice.frames = options.frames;
    }
    choice.frame_error_m = impostor::frameError(pose_positions, choice.frames);
    const gpu::AtlasLayout layout = impostor::atlasLayout(agent_bounds, choice.grid, choice.frames, choice.texel_m);
    model.impostor = std::make_unique<impostor::MultiViewImpostor>(
        impostor::bakeMultiView(renderer_, *model.gpu, layout, choice.grid));
    models_.push_back(std::move(model));
  }
  for (Lists* l : {&lists_, &caster_lists_}) {
    l->geometry.resize(models_.size());
    for (size_t m = 0; m < models_.size(); ++m) l->geometry[m].resize(models_[m].level_m.size());
    l->impostors.resize(models_.size());
  }
}

CrowdRuntime::~CrowdRuntime() = default;

impostor::SwitchDistances CrowdRuntime::switchDistances(size_t m, const Camera& camera) const {
  const Model& model = models_[m];
  return impostor::switchDistances(model.impostor->layout, model.impostor->worst_view_angle, focalOf(camera),
                                   options_.error_px, model.choice.frame_error_m);
}

double CrowdRuntime::bakeSeconds() const {
  double s = 0.0;
  for (const Model& m : models_) s += m.impostor->bake_seconds;
  return s;
}

size_t CrowdRuntime::atlasBytes() const {
  size_t b = 0;
  for (const Model& m : models_) b += m.impostor->byteSize();
  return b;
}

void CrowdRuntime::prepareFrame(const Camera& camera, std::span<const CrowdAgentState> agents) {
  collectGeometryMs();
  budget_triangles_ = options_.max_geometry_triangles > 0 ? options_.max_geometry_triangles : UINT64_MAX;
  if (options_.geometry_ms > 0.0)
    budget_triangles_ = std::min(budget_triangles_, triangle_rate_.trianglesFor(options_.geometry_ms));
  switch_m_.resize(models_.size());
  for (size_t m = 0; m < models_.size(); ++m) switch_m_[m] = switchDistances(m, camera).both();
  lod_m_per_m_ = options_.geometry_lod_px / focalOf(camera);
  // Inside its switch an impostor's error grows as 1 / distance from the bound at the switch: error_px * switch_m
  // pixel-metres, or error_px * switch_m / focal metres over the distance, as a level's distance to the mesh is.
  impostor_m_.resize(models_.size());
  for (size_t m = 0; m < models_.size(); ++m) impostor_m_[m] = options_.error_px * switch_m_[m] / focalOf(camera);
  spheres_.resize(agents.size());
  for (size_t i = 0; i < agents.size(); ++i) {
    const CrowdAgentState& a = agents[i];
    if (a.model >= models_.size())
      throw Error("crowd runtime", "agent of model " + std::to_string(a.model) + " out of range");
    spheres_[i] = {a.position + turn(a.heading, models_[a.model].centre), models_[a.model].radius};
  }
}

namespace {

// The index of `count` poses or frames spread over one cycle that a phase (cycles, any real) shows.
uint32_t cycleIndex(float phase, int count) {
  return uint32_t(std::lround((phase - std::floor(phase)) * float(count))) % uint32_t(count);
}

}  // namespace

gpu::CrowdAgentGpu CrowdRuntime::record(const CrowdAgentState& a) const {
  gpu::CrowdAgentGpu g;
  g.pos_heading = Vec4(a.position, a.heading);
  g.tint = a.tint;
  g.object_id = a.object_id;
  g.outfit = a.outfit;
  return g;
}

void CrowdRuntime::cullBehind(const gpu::RenderTarget& target) {
  target.readDepthRows(depth_rows_);
  occluders_.build(depth_rows_, target.width(), target.height());
  cull_next_ = true;
}

bool CrowdRuntime::hidden(const Mat4& view_proj, const Vec3& centre, float radius) const {
  const Box3 box = Box3::fromPoints(centre - Vec3(radius), centre + Vec3(radius));
  return occluders_.hides(gpu::projectBox(box, view_proj, occluders_.width(), occluders_.height()));
}

void CrowdRuntime::classify(const Camera& camera, std::span<const CrowdAgentState> agents, CrowdPolicy policy,
                            CrowdFrameStats& stats) {
  const bool cull = cull_next_;
  cull_next_ = false;
  if (cull && (occluders_.width() != camera.width || occluders_.height() != camera.height))
    throw Error("crowd runtime", "cullBehind's target is not the camera's size");
  const Mat4 view_proj = camera.viewProjection();
  Frustum frustum = Frustum::fromMatrix(view_proj);
  for (Vec4& p : frustum.planes) p /= std::max(glm::length(Vec3(p)), 1e-20f);
  clearLists(lists_);
  drawn_.assign(agents.size(), Drawn::NotDrawn);
  level_.assign(agents.size(), 0);
  near_.clear();
  const bool budgeted = policy == CrowdPolicy::Mixed && this->budgeted();
  if (budgeted) {
    stats.budget_triangles = budget_triangles_;
    stats.geometry_ms = last_geometry_ms_;
  }
  for (size_t i = 0; i < agents.size(); ++i) {
    const CrowdAgentState& a = agents[i];
    const Vec3 centre = spheres_[i].centre;
    const Model& model = models_[a.model];
    bool visible = true;
    for (const Vec4& p : frustum.planes)
      if (glm::dot(Vec3(p), centre) + p.w < -model.radius) {
        visible = false;
        break;
      }
    if (!visible) continue;
    ++stats.in_view;
    if (cull && hidden(view_proj, centre, model.radius)) {
      ++stats.occluded;
      continue;
    }
    const float distance = glm::length(camera.eye - centre);
    const bool impostor = policy == CrowdPolicy::Impostor ||
                          (policy == CrowdPolicy::Mixed && double(distance) >= switch_m_[a.model]);
    if (!impostor && budgeted) {
      near_.push_back({distance, uint32_t(i)});  // decided by fitBudget
      continue;
    }
    addToLists(camera, a, uint32_t(i), impostor, impostor ? 0 : levelFor(a, distance, policy));
  }
  if (!near_.empty()) fitBudget(camera, agents, stats);
}

void CrowdRuntime::fitBudget(const Camera& camera, std::span<const CrowdAgentState> agents, CrowdFrameStats& stats) {
  // Each agent's ladder: the level the bound gives it, with budget_coarsens the coarser levels whose error (level_m)
  // is under what an impostor inside its switch shows (impostor_m_), then the impostor. Both errors on screen
  // are metres over the agent's distance. While the triangles exceed the budget, the step taken is the agent's whose
  // next rung shows the least: the largest error on screen ends as small as the budget allows.
  const size_t n = near_.size();
  constexpr uint32_t kImpostor = std::numeric_limits<uint32_t>::max();
  auto modelOf = [&](size_t k) -> const Model& { return models_[agents[near_[k].second].model]; };
  auto trianglesAt = [&](size_t k) -> uint64_t {
    return near_level_[k] == kImpostor ? 0 : modelOf(k).gpu->triangleCount(near_level_[k]);
  };
  // Whether the next rung is a coarser level (else the impostor).
  auto coarserLevel = [&](size_t k) {
    const Model& model = modelOf(k);
    const uint32_t l = near_level_[k];
    return options_.budget_coarsens && l + 1 < model.level_m.size() &&
           model.level_m[l + 1] < impostor_m_[agents[near_[k].second].model];
  };
  // The next rung's distance (metres) or -1 at the impostor.
  auto nextMetres = [&](size_t k) {
    const uint32_t l = near_level_[k];
    if (l == kImpostor) return -1.0;
    const Model& model = modelOf(k);
    return coarserLevel(k) ? model.level_m[l + 1] : impostor_m_[agents[near_[k].second].model];
  };
  near_level_.resize(n);
  uint64_t triangles = 0;
  for (size_t k = 0; k < n; ++k) {
    near_level_[k] = levelFor(agents[near_[k].second], near_[k].first, CrowdPolicy::Mixed);
    triangles += trianglesAt(k);
  }
  using Step = std::pair<double, size_t>;  // (next rung's distance on screen, near_ entry)
  std::priority_queue<Step, std::vector<Step>, std::greater<>> steps;
  auto push = [&](size_t k) {
    const double m = nextMetres(k);
    if (m >= 0.0) steps.push({m / std::max(double(near_[k].first), 1e-3), k});
  };
  if (triangles > budget_triangles_)
    for (size_t k = 0; k < n; ++k) push(k);
  while (triangles > budget_triangles_ && !steps.empty()) {
    const size_t k = steps.top().second;
    steps.pop();
    triangles -= trianglesAt(k);
    near_level_[k] = coarserLevel(k) ? near_level_[k] + 1 : kImpostor;
    triangles += trianglesAt(k);
    push(k);
  }
  for (size_t k = 0; k < n; ++k) {
    const auto [distance, i] = near_[k];
    const bool impostor = near_level_[k] == kImpostor;
    stats.over_budget += impostor ? 1 : 0;
    if (!impostor)
      stats.coarsened += near_level_[k] > levelFor(agents[i], distance, CrowdPolicy::Mixed) ? 1 : 0;
    addToLists(camera, agents[i], i, impostor, impostor ? 0 : near_level_[k]);
  }
}

uint32_t CrowdRuntime::levelFor(const CrowdAgentState& a, float distance, CrowdPolicy policy) const {
  const std::vector<double>& level_m = models_[a.model].level_m;
  if (policy != CrowdPolicy::Mixed || level_m.size() < 2) return 0;
  const double allowed = lod_m_per_m_ * double(distance);
  uint32_t level = 0;
  for (uint32_t l = 1; l < level_m.size(); ++l)
    if (level_m[l] <= allowed) level = l;
  return level;
}

void CrowdRuntime::clearLists(Lists& lists) {
  for (size_t m = 0; m < models_.size(); ++m) {
    for (auto& level : lists.geometry[m]) level.clear();
    lists.impostors[m].clear();
  }
}

void CrowdRuntime::addToLists(const Camera& camera, const CrowdAgentState& a, uint32_t i, bool impostor,
                              uint32_t level) {
  const Model& model = models_[a.model];
  gpu::CrowdAgentGpu g = record(a);
  drawn_[i] = impostor ? Drawn::Impostor : Drawn::Geometry;
  if (!impostor) {
    g.index = cycleIndex(a.phase, options_.palette_poses);
    level_[i] = level;
    lists_.geometry[a.model][level].push_back(g);
    return;
  }
  g.index = cycleIndex(a.phase, model.choice.frames);
  const Vec3 local = turn(-a.heading, camera.eye - spheres_[i].centre);  // the eye in agent space
  g.view = uint32_t(impostor::nearestView(model.impostor->grid, glm::length(local) > 0.0f ? local : Vec3(1, 0, 0)));
  lists_.impostors[a.model].push_back(g);
}

double CrowdRuntime::collectGeometryMs() {
  if (geometry_timed_) {  // the last frame's skinned draws (waits for the result if the GPU is still on them)
    last_geometry_ms_ = geometry_timer_->elapsedMs();
    triangle_rate_.observe(last_geometry_ms_, timed_triangles_);
    geometry_timed_ = false;
  }
  return last_geometry_ms_;
}

CrowdFrameStats CrowdRuntime::drawLists(const Camera& camera, const gpu::LightSettings& light, CrowdFrameStats stats) {
  auto add = [&](const gpu::FrameStats& f) {
    stats.draw.triangles += f.triangles;
    stats.draw.draw_calls += f.draw_calls;
    stats.draw.objects += f.objects;
  };
  // The skinned agents first, timed under a budget in milliseconds; then the impostors.
  size_t skinned = 0;
  for (size_t m = 0; m < models_.size(); ++m)
    for (const std::vector<gpu::CrowdAgentGpu>& list : lists_.geometry[m]) skinned += list.size();
  const bool timed = options_.geometry_ms > 0.0 && skinned > 0;
  const uint64_t triangles_before = stats.draw.triangles;
  if (timed) {
    if (!geometry_timer_) geometry_timer_ = std::make_unique<gpu::GpuTimer>();
    geometry_timer_->begin();
  }
  for (size_t m = 0; m < models_.size(); ++m)
    for (size_t l = 0; l < lists_.geometry[m].size(); ++l) {
      const size_t n = lists_.geometry[m][l].size();
      stats.geometry += n;
      stats.coarser += l > 0 ? n : 0;
      add(renderer_.drawSkinned(camera, *models_[m].gpu, lists_.geometry[m][l], light, l));
    }
  if (timed) {
    geometry_timer_->end();
    geometry_timed_ = true;
    timed_triangles_ = stats.draw.triangles - triangles_before;
  }
  for (size_t m = 0; m < models_.size(); ++m) {
    stats.impostors += lists_.impostors[m].size();
    add(renderer_.drawImpostors(camera, *models_[m].impostor->atlas, lists_.impostors[m], light, options_.blend_views));
  }
  return stats;
}

CrowdFrameStats CrowdRuntime::draw(const Camera& camera, std::span<const CrowdAgentState> agents, CrowdPolicy policy,
                                   const gpu::LightSettings& light) {
  CrowdFrameStats stats;
  prepareFrame(camera, agents);
  classify(camera, agents, policy, stats);
  return drawLists(camera, light, stats);
}

void CrowdRuntime::castShadows(const Camera& camera, std::span<const CrowdAgentState> agents, CrowdPolicy policy,
                               const gpu::LightSettings& light, const CrowdShadowOptions& shadows,
                               CrowdFrameStats& stats) {
  const ShadowFit fit = fitShadow(camera, light.direction, spheres_, shadows.distance_m, shadows.map_size);
  if (!shadow_map_ || shadow_map_->size() != shadows.map_size)
    shadow_map_ = std::make_unique<gpu::ShadowMap>(shadows.map_size);
  shadow_map_->bindForCasters();  // cleared: no caster
  shadow_projection_ = fit.projection;
  shadow_screen_ = fit.screen_rects;
  stats.shadow_texel_m = fit.projection.texel_m;
  if (fit.casters.empty()) return;
  const Vec3 to_light = -glm::normalize(light.direction);
  clearLists(caster_lists_);
  // Each caster in the representation the camera's policy gives it; impostors show their view towards the light.
  for (uint32_t i : fit.casters) {
    const CrowdAgentState& a = agents[i];
    const Model& model = models_[a.model];
    gpu::CrowdAgentGpu g = record(a);
    if (!castsAsImpostor(camera, a, i, policy, shadows)) {
      g.index = cycleIndex(a.phase, options_.palette_poses);
      const uint32_t level = drawn_[i] == Drawn::Geometry
                                 ? level_[i]
                                 : levelFor(a, glm::length(camera.eye - spheres_[i].centre), policy);
      caster_lists_.geometry[a.model][level].push_back(g);
    } else {
      g.index = cycleIndex(a.phase, model.choice.frames);
      g.view = uint32_t(impostor::nearestView(model.impostor->grid, turn(-a.heading, to_light)));
      caster_lists_.impostors[a.model].push_back(g);
    }
  }
  for (size_t m = 0; m < models_.size(); ++m) {
    for (size_t l = 0; l < caster_lists_.geometry[m].size(); ++l)
      renderer_.drawSkinnedDepth(fit.projection.view_proj, *models_[m].gpu, caster_lists_.geometry[m][l], l);
    renderer_.drawImpostorDepth(fit.projection.view_proj, to_light, *models_[m].impostor->atlas,
                                caster_lists_.impostors[m]);
  }
  stats.shadow_casters = fit.casters.size();
}

bool CrowdRuntime::castsAsImpostor(const Camera& camera, const CrowdAgentState& a, uint32_t i, CrowdPolicy policy,
                                   const CrowdShadowOptions& shadows) const {
  if (policy != CrowdPolicy::Mixed) return policy == CrowdPolicy::Impostor;
  if (shadows.impostor_casters || drawn_[i] == Drawn::Impostor) return true;
  if (drawn_[i] == Drawn::Geometry) return false;
  // Not drawn (out of view or hidden): by its distance, or as an impostor under a geometry budget, which only the
  // drawn agents share.
  return budgeted() ||
         double(glm::length(camera.eye - spheres_[i].centre)) >= switch_m_[a.model];
}

CrowdFrameStats CrowdRuntime::drawShadowed(const Camera& camera, std::span<const CrowdAgentState> agents,
                                           CrowdPolicy policy, const gpu::LightSettings& light,
                                           const gpu::RenderTarget& target, const CrowdShadowOptions& shadows) {
  CrowdFrameStats stats;
  prepareFrame(camera, agents);
  classify(camera, agents, policy, stats);  // first: the casters are cast as they are drawn
  castShadows(camera, agents, policy, light, shadows, stats);
  target.bindForOpaquePass();
  stats = drawLists(camera, light, stats);
  if (stats.shadow_casters > 0) {
    if (!receiver_) receiver_ = std::make_unique<gpu::ShadowReceiver>();
    receiver_->apply(camera, *shadow_map_, shadow_projection_, target, light, shadows.agent_id_mask, shadows.bias_m,
                     shadows.distance_m, shadow_screen_);
  }
  target.bindForOpaquePass();
  return stats;
}

}  // namespace farfield::runtime
