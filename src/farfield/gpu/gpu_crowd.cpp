#include "farfield/gpu/gpu_crowd.h"

#include <epoxy/gl.h>
#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <cstring>
#include <iterator>
#include <string>

#include "farfield/core/check.h"
#include "farfield/core/error.h"

namespace farfield::gpu {
namespace {

// After a pass that fills the lists: the draws read the records (storage) and the commands (indirect), and the next
// frame's reset copies over the commands, the late readback copies them, and readCounts reads the counts (buffer
// operations).
constexpr GLbitfield kAfterPass = GL_SHADER_STORAGE_BARRIER_BIT | GL_COMMAND_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT;

struct AgentRecord {
  uint32_t route, model, outfit, id;
  float start, speed, direction, phase;
  Vec4 tint;
};
struct RouteRecord {
  uint32_t first, count;
  float length, unused;
};
struct ModelRecord {
  Vec4 sphere;
  Vec4 lists;
  uint32_t counts[4];
  Vec4 grid;
  float level_m[GpuCrowd::kMaxLevels];
  uint32_t level_tris[GpuCrowd::kMaxLevels];
};
struct ListRecord {  // gpu::CrowdAgentGpu
  Vec4 pos_heading, tint;
  uint32_t index, view, object_id, outfit;
};

uint32_t makeBuffer(const void* data, size_t bytes, size_t& total) {
  uint32_t b = 0;
  glCreateBuffers(1, &b);
  glNamedBufferStorage(b, GLsizeiptr(std::max<size_t>(bytes, 16)), data, 0);
  total += bytes;
  return b;
}

template <class T>
std::vector<T> readBuffer(uint32_t buffer, size_t offset, size_t count) {
  std::vector<T> out(count);
  if (count) glGetNamedBufferSubData(buffer, GLintptr(offset), GLsizeiptr(count * sizeof(T)), out.data());
  return out;
}

}  // namespace

GpuCrowd::GpuCrowd(std::span<const GpuCrowdRoute> routes, std::span<const GpuCrowdAgent> agents,
                   std::span<const GpuCrowdModel> models)
    : agents_(agents.size()), models_(models.size()) {
  const char* what = "GPU crowd";
  if (agents.empty()) throw Error(what, "no agents");
  if (models.empty() || models.size() > size_t(kMaxModels))
    throw Error(what, std::to_string(models.size()) + " models (1.." + std::to_string(kMaxModels) + ")");
  std::vector<RouteRecord> route_records;
  std::vector<Vec4> points;
  for (size_t r = 0; r < routes.size(); ++r) {
    const GpuCrowdRoute& route = routes[r];
    if (route.loop.size() < 2 || route.distance.size() != route.loop.size() ||
        (!route.ground.empty() && route.ground.size() != route.loop.size()) || !(route.length > 0.0f))
      throw Error(what, "route " + std::to_string(r) + ": needs 2 or more points, an arc length and a ground height "
                                                         "(or none) at each, and a positive length");
    route_records.push_back({uint32_t(points.size()), uint32_t(route.loop.size()), route.length, 0.0f});
    for (size_t k = 0; k < route.loop.size(); ++k)
      points.emplace_back(route.loop[k], route.distance[k], route.ground.empty() ? 0.0f : route.ground[k]);
  }
  std::vector<AgentRecord> agent_records;
  agent_records.reserve(agents.size());
  for (size_t i = 0; i < agents.size(); ++i) {
    const GpuCrowdAgent& a = agents[i];
    if (a.route >= routes.size() || a.model >= models.size())
      throw Error(what, "agent " + std::to_string(i) + " names route " + std::to_string(a.route) + " and model " +
                            std::to_string(a.model) + " (" + std::to_string(routes.size()) + " routes, " +
                            std::to_string(models.size()) + " models)");
    agent_records.push_back({a.route, a.model, a.outfit, a.id, a.start, a.speed, a.direction, a.phase, a.tint});
  }
  std::vector<ModelRecord> model_records;
  for (size_t m = 0; m < models.size(); ++m) {
    const GpuCrowdModel& mo = models[m];
    if (!(mo.stride_m > 0.0f) || !(mo.radius > 0.0f) || mo.palette_poses < 1 || mo.frames < 1 || mo.azimuths < 1 ||
        mo.elevations < 1)
      throw Error(what, "model " + std::to_string(m) + ": stride, radius, poses, frames and views must be positive");
    if (mo.levels.size() + 1 > size_t(kMaxLevels))
      throw Error(what, "model " + std::to_string(m) + ": " + std::to_string(mo.levels.size() + 1) +
                            " levels of detail (at most " + std::to_string(kMaxLevels) + ")");
    ModelRecord record{Vec4(mo.centre, mo.radius),
                       Vec4(float(2 * m), mo.stride_m, float(mo.geometry_indices / 3), float(mo.levels.size() + 1)),
                       {mo.palette_poses, mo.frames, mo.azimuths, mo.elevations},
                       Vec4(mo.max_elevation, 0.0f, 0.0f, 0.0f),
                       {},
                       {}};
    record.level_tris[0] = mo.geometry_indices / 3;
    for (size_t l = 0; l < mo.levels.size(); ++l) {
      record.level_m[l + 1] = mo.levels[l].distance_m;
      record.level_tris[l + 1] = mo.levels[l].indices / 3;
    }
    model_records.push_back(record);
    level_counts_.push_back(mo.levels.size() + 1);
    initial_commands_.push_back({mo.geometry_indices, 0, mo.geometry_first_index, 0, 0});
    initial_commands_.push_back({4, 0, 0, 0, 0});  // count 4, instances, first 0, base instance 0
  }
  // The casters' lists after the camera's, alike; then levels 1.. of each model, the camera's and the casters'
  // (levelCommand).
  for (size_t k = 0, n = initial_commands_.size(); k < n; ++k) initial_commands_.push_back(initial_commands_[k]);
  for (int pass = 0; pass < 2; ++pass)
    for (const GpuCrowdModel& mo : models)
      for (size_t l = 1; l < size_t(kMaxLevels); ++l)
        initial_commands_.push_back(
            l <= mo.levels.size() ? GpuCrowdCommand{mo.levels[l - 1].indices, 0, mo.levels[l - 1].first_index, 0, 0}
                                  : GpuCrowdCommand{});
  agent_buf_ = makeBuffer(agent_records.data(), agent_records.size() * sizeof(AgentRecord), bytes_);
  routes_ = makeBuffer(route_records.data(), route_records.size() * sizeof(RouteRecord), bytes_);
  points_ = makeBuffer(points.data(), points.size() * sizeof(Vec4), bytes_);
  poses_ = makeBuffer(nullptr, agents.size() * sizeof(Vec4), bytes_);
  phases_ = makeBuffer(nullptr, agents.size() * sizeof(float), bytes_);
  model_buf_ = makeBuffer(model_records.data(), model_records.size() * sizeof(ModelRecord), bytes_);
  commands_ = makeBuffer(initial_commands_.data(), initial_commands_.size() * sizeof(GpuCrowdCommand), bytes_);
  initial_ = makeBuffer(initial_commands_.data(), initial_commands_.size() * sizeof(GpuCrowdCommand), bytes_);
  // 64 records = 3,072 bytes: list offsets (and levels' parts of a list) aligned for binding.
  capacity_ = std::max<size_t>((agents.size() + 63) / 64 * 64, size_t(kMaxLevels) * 64);
  level_capacity_ = capacity_ / size_t(kMaxLevels) / 64 * 64;
  lists_ = makeBuffer(nullptr, 4 * models_ * capacity_ * sizeof(ListRecord), bytes_);  // the camera's, the casters'
  counts_ = makeBuffer(nullptr, 8 * sizeof(uint32_t), bytes_);
  const std::vector<uint32_t> no_levels(2 * size_t(kMaxModels) * size_t(kMaxLevels), 0);  // camera, casters
  level_count_buf_ = makeBuffer(no_levels.data(), no_levels.size() * sizeof(uint32_t), bytes_);
  candidates_ = makeBuffer(nullptr, agents.size() * sizeof(uint32_t), bytes_);
  const std::vector<uint32_t> zero(kBudgetBuckets, 0);
  buckets_ = makeBuffer(zero.data(), zero.size() * sizeof(uint32_t), bytes_);
  simulate_ = Program::computeFromEmbedded("crowd_sim.comp.glsl", "#define FF_SIMULATE 1\n");
  classify_ = Program::computeFromEmbedded("crowd_sim.comp.glsl");
  casters_ = Program::computeFromEmbedded("crowd_sim.comp.glsl", "#define FF_CASTERS 1\n");
  budget_scan_ = Program::computeFromEmbedded("crowd_sim.comp.glsl", "#define FF_BUDGET_SCAN 1\n");
  budget_assign_ = Program::computeFromEmbedded("crowd_sim.comp.glsl", "#define FF_BUDGET_ASSIGN 1\n");
  level_counts_pass_ = Program::computeFromEmbedded("crowd_sim.comp.glsl", "#define FF_LEVEL_COUNTS 1\n");
  late_commands_ = std::make_unique<LateReadback>(initial_commands_.size() * sizeof(GpuCrowdCommand));
}

GpuCrowd::~GpuCrowd() {
  for (uint32_t b : {agent_buf_, routes_, points_, poses_, phases_, model_buf_, commands_, initial_, lists_, counts_,
                     candidates_, buckets_, level_count_buf_})
    if (b) glDeleteBuffers(1, &b);
}

void GpuCrowd::bindBuffers() const {
  const uint32_t buffers[] = {agent_buf_, routes_, points_,  poses_,      phases_, model_buf_,
                              commands_,  lists_,  counts_, candidates_, buckets_, level_count_buf_};
  for (GLuint b = 0; b < GLuint(std::size(buffers)); ++b) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, b, buffers[b]);
}

void GpuCrowd::usePass(const Program& pass, const Camera& camera, std::span<const float> switch_m) const {
  float switches[kMaxModels] = {};
  for (size_t m = 0; m < models_; ++m) switches[m] = switch_m[m];
  pass.use();
  pass.set("u_agents", uint32_t(agents_));
  pass.set("u_eye", camera.eye);
  pass.set("u_capacity", uint32_t(capacity_));
  pass.set("u_budget", uint32_t(0));
  pass.set("u_lod_m_per_m", lod_m_per_m_);
  pass.set("u_level_capacity", uint32_t(level_capacity_));
  pass.set("u_level_command0", uint32_t(4 * models_));
  pass.set("u_models", uint32_t(models_));
  glUniform1fv(pass.uniformLocation("u_switch[0]"), kMaxModels, switches);
  bindBuffers();
}

void GpuCrowd::simulate(float t) {
  simulate_.use();
  simulate_.set("u_agents", uint32_t(agents_));
  simulate_.set("u_time", t);
  bindBuffers();
  glDispatchCompute(GLuint((agents_ + 63) / 64), 1, 1);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);  // (readPoses, readPhases)
}

void GpuCrowd::occludeBehind(const RenderTarget& target) {
  if (!pyramid_) pyramid_ = std::make_unique<GpuDepthPyramid>();
  pyramid_->build(target);
  occlude_next_ = true;
}

void GpuCrowd::castShadows(const Camera& camera, std::span<const float> switch_m, const Mat4& light_view_proj,
                           float side_m, float depth_range_m, const Vec3& to_light) {
  if (switch_m.size() != models_)
    throw Error("GPU crowd", std::to_string(switch_m.size()) + " switch distances for " + std::to_string(models_) +
                                 " models");
  if (!(side_m > 0.0f) || !(depth_range_m > 0.0f)) throw Error("GPU crowd", "an empty shadow map box");
  // The casters' commands (2m .. 4m), reset from their initial values.
  const GLintptr casters = GLintptr(2 * models_ * sizeof(GpuCrowdCommand));
  glCopyNamedBufferSubData(initial_, commands_, casters, casters, casters);
  usePass(casters_, camera, switch_m);
  casters_.set("u_first_list", uint32_t(2 * models_));
  casters_.set("u_budget", uint32_t(budgeted_ ? 1 : 0));  // the last classification's candidates and cut
  casters_.set("u_light_view_proj", light_view_proj);
  casters_.set("u_to_light", glm::normalize(to_light));
  glUniform2f(casters_.uniformLocation("u_light_scale"), 2.0f / side_m, 1.0f / depth_range_m);
  glDispatchCompute(GLuint((agents_ + 63) / 64), 1, 1);
  if (lod_m_per_m_ > 0.0f) countLevels(camera, switch_m, true);
  glMemoryBarrier(kAfterPass);
}

GpuCrowd::Counts GpuCrowd::readCounts() const {
  const std::vector<uint32_t> c = readBuffer<uint32_t>(counts_, 0, 7);
  Counts counts{c[0], c[1]};
  counts.level_overflow = c[6];
  if (budget_ > 0) {
    counts.over_budget = c[3];
    counts.budget_triangles_kept = c[4];
    counts.budget_triangles_wanted = c[5];
  }
  return counts;
}

void GpuCrowd::captureCommands(uint64_t frame) {
  late_commands_->capture(commands_, 0, frame);
}

size_t GpuCrowd::finishedCommands(
    const std::function<void(uint64_t, std::span<const GpuCrowdCommand>)>& use) {
  return late_commands_->finished([&](uint64_t frame, std::span<const uint8_t> bytes) {
    std::vector<GpuCrowdCommand> commands(initial_commands_.size());
    std::memcpy(commands.data(), bytes.data(), bytes.size());
    use(frame, commands);
  });
}

void GpuCrowd::cullAndClassify(const Camera& camera, std::span<const float> switch_m) {
  if (switch_m.size() != models_)
    throw Error("GPU crowd", std::to_string(switch_m.size()) + " switch distances for " + std::to_string(models_) +
                                 " models");
  camera.validate("GPU crowd camera");
  // This pass rewrites the lists and commands that earlier draws read (the last view's, or the shadow casters' in the
  // same buffers); its writes wait for those reads only across this barrier (a write after a read, OpenGL 4.6, 7.13.2;
  // gl_barrier_check.h). After simulate() it costs nothing: simulate's own barrier came just before.
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
  // The instance counts back to 0: the commands copied from their initial values on the GPU's side (no upload).
  glCopyNamedBufferSubData(initial_, commands_, 0, 0, GLsizeiptr(initial_commands_.size() * sizeof(GpuCrowdCommand)));
  glClearNamedBufferData(counts_, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
  Frustum frustum = Frustum::fromMatrix(camera.viewProjection());
  for (Vec4& p : frustum.planes) p /= std::max(glm::length(Vec3(p)), 1e-20f);  // distances in metres
  usePass(classify_, camera, switch_m);
  glUniform4fv(classify_.uniformLocation("u_planes[0]"), 6, glm::value_ptr(frustum.planes[0]));
  const bool occlude = occlude_next_;
  occlude_next_ = false;
  classify_.set("u_occlusion", occlude ? 1 : 0);
  if (occlude) {
    if (pyramid_->levelSizes()[0] != camera.width || pyramid_->levelSizes()[1] != camera.height)
      throw Error("GPU crowd", "occludeBehind's target is not the camera's size");
    classify_.set("u_view_proj", camera.viewProjection());
    classify_.set("u_levels", pyramid_->levels());
    const std::vector<int> sizes = pyramid_->levelSizes();
    glUniform2iv(classify_.uniformLocation("u_level_size[0]"), GLsizei(pyramid_->levels()), sizes.data());
    pyramid_->bind(2, 3);
  }
  // Under a budget: the candidates' buckets over the largest switch distance (a budget means nothing without one).
  float largest_switch = 0.0f;
  for (float d : switch_m)
    if (d < 1e30f) largest_switch = std::max(largest_switch, d);
  const bool budget = budget_ > 0 && largest_switch > 0.0f;
  budgeted_ = budget;
  const uint32_t budget_triangles = uint32_t(std::min<uint64_t>(budget_, UINT32_MAX));
  if (budget) {
    classify_.set("u_budget", budget_triangles);
    classify_.set("u_buckets", kBudgetBuckets);
    classify_.set("u_buckets_per_m", float(kBudgetBuckets) / largest_switch);
  }
  glDispatchCompute(GLuint((agents_ + 63) / 64), 1, 1);
  if (budget) {
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    budget_scan_.use();
    budget_scan_.set("u_budget", budget_triangles);
    budget_scan_.set("u_buckets", kBudgetBuckets);
    glDispatchCompute(1, 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    usePass(budget_assign_, camera, switch_m);
    glDispatchCompute(GLuint((agents_ + 63) / 64), 1, 1);
  }
  if (lod_m_per_m_ > 0.0f) countLevels(camera, switch_m, false);
  glMemoryBarrier(kAfterPass);
  if (occlude) {
    glBindTextureUnit(2, 0);
    glBindTextureUnit(3, 0);
  }
}

std::vector<Vec4> GpuCrowd::readPoses() const { return readBuffer<Vec4>(poses_, 0, agents_); }
std::vector<float> GpuCrowd::readPhases() const { return readBuffer<float>(phases_, 0, agents_); }
std::vector<GpuCrowdCommand> GpuCrowd::readCommands() const {
  return readBuffer<GpuCrowdCommand>(commands_, 0, initial_commands_.size());
}
std::vector<uint32_t> GpuCrowd::readIds(size_t offset, size_t command) const {
  const size_t n = readCommands()[command].instance_count;
  std::vector<uint32_t> ids;
  for (const ListRecord& r : readBuffer<ListRecord>(lists_, offset, n)) ids.push_back(r.object_id);
  return ids;
}
std::vector<uint32_t> GpuCrowd::readList(size_t list) const {
  FF_CHECK(list < 4 * models_);
  return readIds(listOffset(list), list);
}
void GpuCrowd::countLevels(const Camera& camera, std::span<const float> switch_m, bool casters) {
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
  usePass(level_counts_pass_, camera, switch_m);
  level_counts_pass_.set("u_first_list", uint32_t(casters ? 2 * models_ : 0));
  glDispatchCompute(1, 1, 1);
}

std::vector<uint32_t> GpuCrowd::readLevelList(size_t m, size_t level, bool caster) const {
  FF_CHECK(m < models_ && level < size_t(kMaxLevels));
  return readIds(levelListOffset(m, level, caster), levelCommand(m, level, caster));
}
size_t GpuCrowd::gpuBytes() const { return bytes_; }

}  // namespace farfield::gpu
