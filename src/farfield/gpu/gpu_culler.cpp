#include "farfield/gpu/gpu_culler.h"

#include <epoxy/gl.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <string>

#include "farfield/core/check.h"
#include "farfield/core/error.h"
#include "farfield/gpu/gpu_depth_pyramid.h"
#include "farfield/gpu/late_readback.h"
#include "farfield/gpu/program.h"
#include "farfield/gpu/stage_clock.h"

namespace farfield::gpu {
namespace {

constexpr GLuint kWorkGroup = 64;        // gpu_cull.comp.glsl's local size
constexpr GLuint kMaxGroupsX = 65535;    // dispatches wider than this go into y
constexpr size_t kCommandBytes = 5 * sizeof(uint32_t);
constexpr size_t kStatCount = 10;        // gpu_cull.comp.glsl's statistics
constexpr size_t kRing = 8;              // frames of statistics in flight
constexpr int kMaxLevels = 16;
// After each stage: its storage writes are read by the next stages, its list lengths by indirect dispatches and its
// commands and counts by indirect draws, and its lists, counts and statistics are cleared or copied by buffer
// operations (the next phase's, the next frame's, the statistics' late readback). Every write is followed by one such
// barrier within its frame (the barrier check, gl_barrier_check.h, finds none missing).
constexpr GLbitfield kAfterStage =
    GL_SHADER_STORAGE_BARRIER_BIT | GL_COMMAND_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT;

enum Variant { kPlain = 0, kTextured = 1, kItems = 2, kVariants = 3 };

GLuint createBuffer(size_t bytes, const void* data, GLbitfield flags = GL_DYNAMIC_STORAGE_BIT) {
  return createStorageBuffer(bytes, data, flags);
}

// Empties a list (gpu_cull.comp.glsl's Work and DrawnList): no work groups, a z of 1, length 0. The stages that append
// to it grow its dispatch.
void clearList(GLuint list) {
  static constexpr std::array<uint32_t, 4> kEmpty{0, 0, 1, 0};
  glClearNamedBufferSubData(list, GL_RGBA32UI, 0, 4 * sizeof(uint32_t), GL_RGBA_INTEGER, GL_UNSIGNED_INT,
                            kEmpty.data());
}

}  // namespace

struct GpuCuller::Impl {
  // The culling stages (gpu_cull.comp.glsl): parts (which also size the work list's dispatch), clusters, draw
  // commands.
  Program parts = Program::computeFromEmbedded("gpu_cull.comp.glsl", "#define FF_STAGE_PARTS 1");
  Program cull = Program::computeFromEmbedded("gpu_cull.comp.glsl", "#define FF_STAGE_CLUSTERS 1");
  Program emit = Program::computeFromEmbedded("gpu_cull.comp.glsl", "#define FF_STAGE_EMIT 1");
  std::array<Program, kVariants> draw{
      Program::fromEmbedded("arena.vert.glsl", "mesh.frag.glsl", "#define FF_ARENA 1"),
      Program::fromEmbedded("arena.vert.glsl", "mesh.frag.glsl", "#define FF_ARENA 1\n#define FF_TEXTURED 1"),
      Program::fromEmbedded("arena.vert.glsl", "mesh.frag.glsl", "#define FF_ARENA 1\n#define FF_ITEM_BUFFER 1")};

  struct CullLocations {
    int view_proj, planes, eye, viewport, phase, compact, cone, count, levels, level_size, margin, frame, lod_px,
        lod_scale, listed;
  };
  CullLocations cl{}, part_l{}, emit_l{};
  struct DrawLocations {
    int view_proj, light_dir, light_color, ambient;
  };
  std::array<DrawLocations, kVariants> dl{};

  GLuint enabled = 0, visibility = 0, stats = 0, group_first = 0, object_frame = 0, work = 0, drawn = 0;
  GLuint drawn_list = 0;  // the instances drawn in this frame (the history pass's work list)
  GLuint part_visible = 0, instance_part = 0;  // per part: visible last frame, in view; per instance: its part
  // The parts of the plan's objects (ascending), which the part stage runs over when not every object is drawn: a
  // frame's culling work follows the plan, not the scene.
  GLuint part_list = 0;
  std::vector<uint32_t> list;
  // Per phase: the commands, and the number written per group (buffers of their own: bound whole, no offset
  // alignment to respect).
  std::array<GLuint, 2> commands{}, counts{};
  uint32_t groups = 0;
  uint32_t instances = 0;

  // The plan's objects: enabled_ids (sorted), or all.
  bool all_enabled = true;
  std::vector<uint32_t> enabled_ids, next_ids;
  std::vector<uint32_t> changes;

  // The depth pyramid (level 0 is the target's depth).
  GpuDepthPyramid pyramid;

  std::unique_ptr<LateReadback> late_stats;  // the statistics, read frames later
  std::unique_ptr<StageClock> stage_clock;   // GpuCullOptions::stage_times

  static CullLocations locate(const Program& program) {
    const GLuint c = program.handle();
    return {glGetUniformLocation(c, "u_view_proj"), glGetUniformLocation(c, "u_planes"),
            glGetUniformLocation(c, "u_eye"),       glGetUniformLocation(c, "u_viewport"),
            glGetUniformLocation(c, "u_phase"),     glGetUniformLocation(c, "u_compact"),
            glGetUniformLocation(c, "u_cone"),      glGetUniformLocation(c, "u_count"),
            glGetUniformLocation(c, "u_levels"),    glGetUniformLocation(c, "u_level_size"),
            glGetUniformLocation(c, "u_margin"),    glGetUniformLocation(c, "u_frame"),
            glGetUniformLocation(c, "u_lod_px"),    glGetUniformLocation(c, "u_lod_scale"),
            glGetUniformLocation(c, "u_listed")};
  }

  Impl() {
    cl = locate(cull);
    part_l = locate(parts);
    emit_l = locate(emit);
    for (int v = 0; v < kVariants; ++v) {
      const GLuint h = draw[size_t(v)].handle();
      dl[size_t(v)] = {glGetUniformLocation(h, "u_view_proj"), glGetUniformLocation(h, "u_light_dir"),
                       glGetUniformLocation(h, "u_light_color"), glGetUniformLocation(h, "u_ambient")};
    }
  }

  ~Impl() {
    const GLuint buffers[] = {enabled,     visibility,  stats,     group_first, object_frame,
                              commands[0], commands[1], counts[0], counts[1],   work,        drawn,
                              drawn_list,  part_visible, instance_part, part_list};
    glDeleteBuffers(GLsizei(std::size(buffers)), buffers);
  }

  // Pyramid levels for a width x height target (GpuDepthPyramid), their sizes into the stages that test them.
  void sizePyramid(int w, int h) {
    if (!pyramid.resize(w, h)) return;
    FF_CHECK_MSG(pyramid.levels() <= kMaxLevels, "render target too large for the depth pyramid");
    const std::vector<int> sizes = pyramid.levelSizes();
    glProgramUniform2iv(cull.handle(), cl.level_size, GLsizei(pyramid.levels()), sizes.data());
    glProgramUniform2iv(parts.handle(), part_l.level_size, GLsizei(pyramid.levels()), sizes.data());
  }
};

GpuCuller::GpuCuller(const SceneArena& arena, const GpuCullOptions& options)
    : arena_(arena), options_(options), impl_(std::make_unique<Impl>()) {
  Impl& im = *impl_;
  core_count_ = epoxy_gl_version() >= 46;
  indirect_count_ = options.compact && (core_count_ || epoxy_has_gl_extension("GL_ARB_indirect_parameters"));
  const size_t objects = arena.scene().objects.size();
  im.instances = uint32_t(arena.instances().size());
  im.groups = uint32_t(arena.groups().size());
  const std::vector<uint32_t> ones(std::max<size_t>(objects, 1), 1u);
  im.enabled = createBuffer(ones.size() * sizeof(uint32_t), ones.data());
  im.object_frame = createBuffer(ones.size() * sizeof(uint32_t), nullptr);
  glClearNamedBufferData(im.object_frame, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
  im.visibility = createBuffer(size_t(im.instances) * sizeof(uint32_t), nullptr);
  glClearNamedBufferData(im.visibility, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
  im.drawn = createBuffer(size_t(im.instances) * sizeof(uint32_t), nullptr);
  glClearNamedBufferData(im.drawn, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
  // The work list: the dispatch of the cluster stages (x, y, z) and its length, then the instances.
  im.work = createBuffer((4 + size_t(im.instances)) * sizeof(uint32_t), nullptr);
  im.drawn_list = createBuffer((4 + size_t(im.instances)) * sizeof(uint32_t), nullptr);
  im.part_visible = createBuffer(arena.parts().size() * sizeof(uint32_t), nullptr);
  im.part_list = createBuffer(std::max<size_t>(arena.parts().size(), 1) * sizeof(uint32_t), nullptr);
  glClearNamedBufferData(im.part_list, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);  // (read only when listed)
  glClearNamedBufferData(im.part_visible, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
  std::vector<uint32_t> part_of(std::max<size_t>(im.instances, 1), 0);
  for (uint32_t p = 0; p < arena.parts().size(); ++p)
    for (uint32_t k = 0; k < arena.parts()[p].instance_count + arena.parts()[p].lod_instance_count; ++k)
      part_of[arena.parts()[p].first_instance + k] = p;
  im.instance_part = createBuffer(part_of.size() * sizeof(uint32_t), part_of.data());
  for (GLuint& c : im.commands) {
    c = createBuffer(size_t(im.instances) * kCommandBytes, nullptr);
    glClearNamedBufferData(c, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
  }
  for (GLuint& c : im.counts) c = createBuffer(size_t(im.groups) * sizeof(uint32_t), nullptr);
  im.stats = createBuffer(kStatCount * sizeof(uint32_t), nullptr);
  std::vector<uint32_t> first(std::max<size_t>(im.groups, 1), 0);
  for (uint32_t g = 0; g < im.groups; ++g) first[g] = arena.groups()[g].first_instance;
  im.group_first = createBuffer(first.size() * sizeof(uint32_t), first.data());
  im.late_stats = std::make_unique<LateReadback>(kStatCount * sizeof(uint32_t), kRing);
  if (options_.stage_times) im.stage_clock = std::make_unique<StageClock>(kGpuCullStages.size() + 1, kRing);
}

GpuCuller::~GpuCuller() = default;

void GpuCuller::setAllObjects() {
  Impl& im = *impl_;
  if (im.all_enabled) return;
  const size_t objects = arena_.scene().objects.size();
  if (objects > 0) {
    const uint32_t one = 1;
    glClearNamedBufferSubData(im.enabled, GL_R32UI, 0, GLsizeiptr(objects * sizeof(uint32_t)), GL_RED_INTEGER,
                              GL_UNSIGNED_INT, &one);
  }
  im.all_enabled = true;
  im.enabled_ids.clear();
}

void GpuCuller::setObjects(std::span<const uint32_t> ids) {
  Impl& im = *impl_;
  const size_t objects = arena_.scene().objects.size();
  im.next_ids.assign(ids.begin(), ids.end());
  if (!std::is_sorted(im.next_ids.begin(), im.next_ids.end())) std::sort(im.next_ids.begin(), im.next_ids.end());
  im.next_ids.erase(std::unique(im.next_ids.begin(), im.next_ids.end()), im.next_ids.end());
  if (!im.next_ids.empty() && (im.next_ids.front() == 0 || im.next_ids.back() > objects))
    throw Error("object id " + std::to_string(im.next_ids.front() == 0 ? 0u : im.next_ids.back()),
                "out of range (the scene has " + std::to_string(objects) + " objects, ids from 1)");
  const bool was_all = im.all_enabled;
  if (im.all_enabled) {
    // From all to a list: clear everything once, then set the list.
    if (objects > 0) glClearNamedBufferData(im.enabled, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
    im.enabled_ids.clear();
    im.all_enabled = false;
  }
  // The symmetric difference of the sorted lists: objects whose state changes.
  im.changes.clear();
  std::set_symmetric_difference(im.enabled_ids.begin(), im.enabled_ids.end(), im.next_ids.begin(),
                                im.next_ids.end(), std::back_inserter(im.changes));
  // Runs of consecutive ids go up in one call each, with the new state of each.
  std::vector<uint32_t> values;
  for (size_t i = 0; i < im.changes.size();) {
    size_t j = i + 1;
    while (j < im.changes.size() && im.changes[j] == im.changes[j - 1] + 1) ++j;
    values.resize(j - i);
    for (size_t k = i; k < j; ++k)
      values[k - i] = std::binary_search(im.next_ids.begin(), im.next_ids.end(), im.changes[k]) ? 1u : 0u;
    glNamedBufferSubData(im.enabled, GLintptr(im.changes[i] - 1) * GLintptr(sizeof(uint32_t)),
                         GLsizeiptr(values.size() * sizeof(uint32_t)), values.data());
    i = j;
  }
  std::swap(im.enabled_ids, im.next_ids);
  if (im.changes.empty() && !was_all) return;
  // The plan's parts, for the part stage: work in the size of the plan.
  im.list.clear();
  for (const uint32_t id : im.enabled_ids) {
    const auto [first, end] = arena_.objectParts(id - 1);
    for (uint32_t p = first; p < end; ++p) im.list.push_back(p);
  }
  if (!im.list.empty())
    glNamedBufferSubData(im.part_list, 0, GLsizeiptr(im.list.size() * sizeof(uint32_t)), im.list.data());
}

void GpuCuller::setLodErrorPx(float px) {
  FF_CHECK(px >= 0.0f && std::isfinite(px));
  options_.lod_error_px = px;
}

void GpuCuller::resetHistory() {
  glClearNamedBufferData(impl_->visibility, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
  glClearNamedBufferData(impl_->part_visible, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
}

void GpuCuller::setOcclusion(bool on) {
  if (on == options_.occlusion) return;
  if (on) resetHistory();
  options_.occlusion = on;
}

FrameStats GpuCuller::draw(const Camera& camera, RenderTarget& target, RenderMode mode, const LightSettings& light) {
  camera.validate("camera");
  Impl& im = *impl_;
  FrameStats stats;
  const uint64_t frame = frames_++;
  im.sizePyramid(target.width(), target.height());
  target.bindForOpaquePass();
  if (im.instances == 0) return stats;

  // ---- per-frame uniforms ----
  const Mat4 view_proj = camera.viewProjection();
  const Frustum frustum = Frustum::fromMatrix(view_proj);
  const GLuint c = im.cull.handle();
  glProgramUniformMatrix4fv(c, im.cl.view_proj, 1, GL_FALSE, glm::value_ptr(view_proj));
  glProgramUniform4fv(c, im.cl.planes, 6, glm::value_ptr(frustum.planes[0]));
  glProgramUniform3fv(c, im.cl.eye, 1, glm::value_ptr(camera.eye));
  glProgramUniform2i(c, im.cl.viewport, target.width(), target.height());
  glProgramUniform1i(c, im.cl.cone, options_.cone ? 1 : 0);
  glProgramUniform1f(c, im.cl.margin, options_.occlusion_margin);
  glProgramUniform1i(c, im.cl.levels, im.pyramid.levels());
  glProgramUniform1ui(c, im.cl.frame, uint32_t(frame + 1));
  const GLuint pp = im.parts.handle();
  glProgramUniformMatrix4fv(pp, im.part_l.view_proj, 1, GL_FALSE, glm::value_ptr(view_proj));
  glProgramUniform4fv(pp, im.part_l.planes, 6, glm::value_ptr(frustum.planes[0]));
  glProgramUniform2i(pp, im.part_l.viewport, target.width(), target.height());
  glProgramUniform1f(pp, im.part_l.margin, options_.occlusion_margin);
  glProgramUniform1i(pp, im.part_l.levels, im.pyramid.levels());
  const uint32_t part_count = uint32_t(im.all_enabled ? arena_.parts().size() : im.list.size());
  glProgramUniform1ui(pp, im.part_l.count, part_count);
  glProgramUniform1i(pp, im.part_l.listed, im.all_enabled ? 0 : 1);
  glProgramUniform3fv(pp, im.part_l.eye, 1, glm::value_ptr(camera.eye));
  glProgramUniform1f(pp, im.part_l.lod_px, options_.lod_error_px);
  // Pixels per unit of error at distance 1 (partLodErrorPx's pixels_per_unit).
  glProgramUniform1f(pp, im.part_l.lod_scale,
                     float(double(target.height()) / (2.0 * std::tan(0.5 * double(camera.fov_y)))));
  const GLuint e = im.emit.handle();
  glProgramUniform1i(e, im.emit_l.compact, indirect_count_ ? 1 : 0);
  glProgramUniform1ui(e, im.emit_l.count, im.instances);
  Vec3 light_dir = light.direction;
  light_dir = glm::length(light_dir) > 0.0f ? glm::normalize(light_dir) : Vec3(0.0f, 0.0f, -1.0f);
  const int variant_of_mode = mode == RenderMode::ItemBuffer ? kItems : -1;
  for (int v = 0; v < kVariants; ++v) {
    if (variant_of_mode >= 0 ? v != variant_of_mode : v == kItems) continue;
    const GLuint h = im.draw[size_t(v)].handle();
    const Impl::DrawLocations& l = im.dl[size_t(v)];
    glProgramUniformMatrix4fv(h, l.view_proj, 1, GL_FALSE, glm::value_ptr(view_proj));
    if (l.light_dir >= 0) glProgramUniform3fv(h, l.light_dir, 1, glm::value_ptr(light_dir));
    if (l.light_color >= 0) glProgramUniform3fv(h, l.light_color, 1, glm::value_ptr(light.color));
    if (l.ambient >= 0) glProgramUniform1f(h, l.ambient, light.ambient);
  }

  // ---- buffers ----
  const SceneArena::Buffers& b = arena_.buffers();
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, b.clusters);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, b.instances);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, b.objects);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, b.materials);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, im.enabled);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 5, im.visibility);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 8, im.group_first);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 10, im.object_frame);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 11, b.parts);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 12, im.work);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 13, im.drawn);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 14, im.drawn_list);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 15, im.part_visible);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 16, im.instance_part);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 17, im.part_list);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 9, im.stats);
  for (GLuint buffer : {im.counts[0], im.counts[1], im.stats})
    glClearNamedBufferData(buffer, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
  clearList(im.drawn_list);

  // A phase's work list: the parts it takes put their clusters on it (PARTS, by phase) and size the cluster stages'
  // dispatch with it.
  const GLuint part_groups = (part_count + kWorkGroup - 1) / kWorkGroup;
  auto listParts = [&](int phase) {
    clearList(im.work);
    glProgramUniform1i(pp, im.part_l.phase, phase);
    glUseProgram(pp);
    glBindTextureUnit(2, target.depthTexture().handle());
    glBindTextureUnit(3, im.pyramid.texture());
    glDispatchCompute(std::min(part_groups, kMaxGroupsX), (part_groups + kMaxGroupsX - 1) / kMaxGroupsX, 1);
    glMemoryBarrier(kAfterStage);
    glBindTextureUnit(2, 0);
    glBindTextureUnit(3, 0);
    glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, im.work);
  };

  // The depth pyramid of what the target holds now (DepthPyramid::build on the GPU).
  auto buildPyramid = [&]() { im.pyramid.build(target); };

  // The cluster stage over the bound work list, in a phase.
  auto testClusters = [&](int phase) {
    glProgramUniform1i(c, im.cl.phase, phase);
    glUseProgram(c);
    // Units 2 and 3: the depth and the pyramid, unbound again before anything draws into the depth.
    glBindTextureUnit(2, target.depthTexture().handle());
    glBindTextureUnit(3, im.pyramid.texture());
    glDispatchComputeIndirect(0);
    glMemoryBarrier(kAfterStage);
    glBindTextureUnit(2, 0);
    glBindTextureUnit(3, 0);
  };

  auto cullPhase = [&](int phase, int commands) {
    testClusters(phase);
    // Runs of drawn clusters into commands.
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 6, im.commands[size_t(commands)]);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 7, im.counts[size_t(commands)]);
    if (!indirect_count_)  // every slot is drawn: those of no run must be empty
      glClearNamedBufferData(im.commands[size_t(commands)], GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
    glUseProgram(e);
    glDispatchComputeIndirect(0);
    glMemoryBarrier(kAfterStage);
  };

  auto drawPhase = [&](int commands) {
    glBindVertexArray(b.vertex_array);
    glBindBuffer(GL_DRAW_INDIRECT_BUFFER, im.commands[size_t(commands)]);
    if (indirect_count_) glBindBuffer(GL_PARAMETER_BUFFER_ARB, im.counts[size_t(commands)]);
    int current = -1;
    bool culling = true, mirrored = false;
    for (uint32_t g = 0; g < im.groups; ++g) {
      const MaterialGroup& group = arena_.groups()[g];
      if (group.instance_count == 0) continue;
      const int variant = mode == RenderMode::ItemBuffer ? kItems : (group.texture_array >= 0 ? kTextured : kPlain);
      if (variant != current) {
        im.draw[size_t(variant)].use();
        current = variant;
      }
      if (variant == kTextured) glBindTextureUnit(0, arena_.textureArray(group.texture_array));
      if (group.double_sided == culling) {
        culling = !group.double_sided;
        if (culling) glEnable(GL_CULL_FACE);
        else glDisable(GL_CULL_FACE);
      }
      if (group.mirrored != mirrored) {
        mirrored = group.mirrored;
        glFrontFace(mirrored ? GL_CW : GL_CCW);
      }
      const void* offset = reinterpret_cast<const void*>(uintptr_t(group.first_instance) * kCommandBytes);
      if (indirect_count_ && core_count_) {
        glMultiDrawElementsIndirectCount(GL_TRIANGLES, GL_UNSIGNED_INT, offset, GLintptr(g * sizeof(uint32_t)),
                                         GLsizei(group.instance_count), GLsizei(kCommandBytes));
      } else if (indirect_count_) {
        glMultiDrawElementsIndirectCountARB(GL_TRIANGLES, GL_UNSIGNED_INT, offset, GLintptr(g * sizeof(uint32_t)),
                                            GLsizei(group.instance_count), GLsizei(kCommandBytes));
      } else {
        glMultiDrawElementsIndirect(GL_TRIANGLES, GL_UNSIGNED_INT, offset, GLsizei(group.instance_count),
                                    GLsizei(kCommandBytes));
      }
      ++stats.draw_calls;
    }
    if (!culling) glEnable(GL_CULL_FACE);
    if (mirrored) glFrontFace(GL_CCW);
    glBindVertexArray(0);
    // Left bound, the count buffer turned later plain indirect draws of other renderers into nothing on Mesa
    // (the GPU crowd's, drawn after this frame's city).
    glBindBuffer(GL_DRAW_INDIRECT_BUFFER, 0);
    if (indirect_count_) glBindBuffer(GL_PARAMETER_BUFFER_ARB, 0);
  };

  // Marks between the stages (kGpuCullStages) when they are timed.
  StageClock* clock = im.stage_clock.get();
  auto mark = [clock](size_t stage_end) {
    if (clock) clock->mark(stage_end);
  };
  if (clock) clock->beginFrame(frame);
  if (!options_.occlusion) {
    listParts(2);
    cullPhase(2, 1);
    mark(1);
    drawPhase(1);
    mark(2);
  } else {
    listParts(0);
    cullPhase(0, 0);
    mark(1);
    drawPhase(0);
    mark(2);
    buildPyramid();
    mark(3);
    listParts(1);
    cullPhase(1, 1);
    mark(4);
    drawPhase(1);
    mark(5);
    if (options_.refine_history) {
      // The drawn instances become the work list (the cluster stage sized its dispatch as it appended them), tested
      // against the final depth, which also decides the parts' visibility (cleared first).
      buildPyramid();
      glClearNamedBufferData(im.part_visible, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 12, im.drawn_list);
      glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, im.drawn_list);
      testClusters(3);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 12, im.work);
    }
  }
  mark(kGpuCullStages.size());
  glUseProgram(0);

  // ---- statistics, read frames later ----
  im.late_stats->capture(im.stats, 0, frame);
  return stats;
}

std::vector<GpuStageTimes> GpuCuller::finishedStageTimes() {
  std::vector<GpuStageTimes> out;
  if (!impl_->stage_clock) return out;
  impl_->stage_clock->finished([&](uint64_t frame, std::span<const double> ms) {
    GpuStageTimes t;
    t.frame = frame;
    std::copy(ms.begin(), ms.end(), t.ms.begin());
    out.push_back(t);
  });
  return out;
}

std::vector<GpuCullStats> GpuCuller::finishedStats() {
  std::vector<GpuCullStats> out;
  impl_->late_stats->finished([&](uint64_t frame, std::span<const uint8_t> bytes) {
    uint32_t v[kStatCount];
    std::memcpy(v, bytes.data(), sizeof(v));
    GpuCullStats st;
    st.frame = frame;
    st.instances_in_plan = v[0];
    st.commands = v[9];
    st.drawn_early = v[1];
    st.drawn_late = v[2];
    st.triangles = uint64_t(v[3]) + uint64_t(v[4]);
    st.frustum_culled = v[5];
    st.cone_culled = v[6];
    st.occlusion_culled = v[7];
    st.objects = v[8];
    out.push_back(st);
  });
  return out;
}

}  // namespace farfield::gpu
