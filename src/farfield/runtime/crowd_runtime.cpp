#include "farfield/runtime/crowd_runtime.h"

#include <algorithm>
#include <cmath>

#include "farfield/core/error.h"

namespace farfield::runtime {

CrowdRuntime::CrowdRuntime(std::span<const scene::SkinnedModel> models,
                           std::span<const CrowdModelOptions> model_options, const CrowdRuntimeOptions& options)
    : options_(options) {
  if (models.size() != model_options.size()) throw Error("crowd runtime", "one option set per model");
  if (options.frames < 1 || options.palette_poses < options.frames || options.palette_poses % options.frames != 0)
    throw Error("crowd runtime", "palette poses must be a positive multiple of the impostor frames");
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
    const Mat4 turn = glm::rotate(Mat4(1.0f), float(degToRad(model_options[m].facing_deg)), Vec3(0, 0, 1));
    Box3 raw;
    for (int p = 0; p < options.palette_poses; p += std::max(1, options.palette_poses / 8))
      for (const Vec3& v : scene::skinMesh(sm, poses[size_t(p)]).positions) raw.expand(Vec3(turn * Vec4(v, 1.0f)));
    const float height = raw.hi.z - raw.lo.z;
    if (!(height > 0.0f)) throw Error(sm.name, "the animated model has no height");
    const float s = model_options[m].height_m / height;
    const Vec3 c = raw.center();
    const Mat4 to_agent = glm::scale(Mat4(1.0f), Vec3(s)) * glm::translate(Mat4(1.0f), Vec3(-c.x, -c.y, -raw.lo.z)) * turn;
    model.gpu = std::make_unique<gpu::SkinnedGpuModel>(sm, to_agent, poses);
    Box3 agent_bounds;
    for (const auto& pose : poses)
      for (const Vec3& v : scene::skinMesh(sm, pose).positions) agent_bounds.expand(Vec3(to_agent * Vec4(v, 1.0f)));
    model.centre = agent_bounds.center();
    model.radius = glm::length(agent_bounds.hi - model.centre);
    const gpu::AtlasLayout layout = impostor::atlasLayout(agent_bounds, options.grid, options.frames, options.texel_m);
    model.impostor = std::make_unique<impostor::MultiViewImpostor>(
        impostor::bakeMultiView(renderer_, *model.gpu, layout, options.grid));
    models_.push_back(std::move(model));
  }
  geometry_.resize(models_.size());
  impostors_.resize(models_.size());
}

CrowdRuntime::~CrowdRuntime() = default;

impostor::SwitchDistances CrowdRuntime::switchDistances(size_t m, const Camera& camera) const {
  const double focal = double(camera.height) / (2.0 * std::tan(double(camera.fov_y) / 2.0));
  return impostor::switchDistances(models_[m].impostor->layout, options_.grid, focal, options_.error_px);
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

CrowdFrameStats CrowdRuntime::draw(const Camera& camera, std::span<const CrowdAgentState> agents, CrowdPolicy policy,
                                   const gpu::LightSettings& light) {
  CrowdFrameStats stats;
  Frustum frustum = Frustum::fromMatrix(camera.viewProjection());
  for (Vec4& p : frustum.planes) p /= std::max(glm::length(Vec3(p)), 1e-20f);
  std::vector<double> switch_m(models_.size());
  for (size_t m = 0; m < models_.size(); ++m) {
    geometry_[m].clear();
    impostors_[m].clear();
    switch_m[m] = switchDistances(m, camera).both();
  }
  const int frames = options_.frames;
  for (const CrowdAgentState& a : agents) {
    if (a.model >= models_.size()) throw Error("crowd runtime", "agent of model " + std::to_string(a.model) + " out of range");
    const Model& model = models_[a.model];
    const float c = std::cos(a.heading), s = std::sin(a.heading);
    const Vec3 centre = a.position + Vec3(c * model.centre.x - s * model.centre.y, s * model.centre.x + c * model.centre.y,
                                          model.centre.z);
    bool visible = true;
    for (const Vec4& p : frustum.planes)
      if (glm::dot(Vec3(p), centre) + p.w < -model.radius) {
        visible = false;
        break;
      }
    if (!visible) continue;
    ++stats.in_view;
    float phase = a.phase - std::floor(a.phase);
    gpu::CrowdAgentGpu g;
    g.pos_heading = Vec4(a.position, a.heading);
    g.tint = a.tint;
    g.object_id = a.object_id;
    const Vec3 to_eye = camera.eye - centre;
    const bool impostor = policy == CrowdPolicy::Impostor ||
                          (policy == CrowdPolicy::Mixed && double(glm::length(to_eye)) >= switch_m[a.model]);
    if (!impostor) {
      g.index = uint32_t(std::lround(phase * float(options_.palette_poses))) % uint32_t(options_.palette_poses);
      geometry_[a.model].push_back(g);
      continue;
    }
    g.index = uint32_t(std::lround(phase * float(frames))) % uint32_t(frames);
    // The view direction in agent space: the eye turned back by the heading.
    const Vec3 local(c * to_eye.x + s * to_eye.y, -s * to_eye.x + c * to_eye.y, to_eye.z);
    g.view = uint32_t(impostor::nearestView(model.impostor->grid, glm::length(local) > 0.0f ? local : Vec3(1, 0, 0)));
    impostors_[a.model].push_back(g);
  }
  for (size_t m = 0; m < models_.size(); ++m) {
    stats.geometry += geometry_[m].size();
    stats.impostors += impostors_[m].size();
    auto add = [&](const gpu::FrameStats& f) {
      stats.draw.triangles += f.triangles;
      stats.draw.draw_calls += f.draw_calls;
      stats.draw.objects += f.objects;
    };
    add(renderer_.drawSkinned(camera, *models_[m].gpu, geometry_[m], light));
    add(renderer_.drawImpostors(camera, *models_[m].impostor->atlas, impostors_[m], light));
  }
  return stats;
}

}  // namespace farfield::runtime
