#include "farfield/gpu/crowd_renderer.h"

#include <epoxy/gl.h>

#include <cstddef>
#include <cstring>
#include <string>

#include "farfield/core/check.h"
#include "farfield/core/error.h"

namespace farfield::gpu {
namespace {

struct SkinVertex {
  float position[3];
  float normal[3];
  float uv[2];
  uint16_t joints[4];
  float weights[4];
};
static_assert(sizeof(SkinVertex) == 56);

// One vertex of one pose, skinned (BakedPoses; std430 in skin.vert.glsl).
struct BakedVertex {
  Vec4 position;  // w unused
  Vec4 normal;    // w unused
};
static_assert(sizeof(BakedVertex) == 32);

// Every pose's vertices skinned on the CPU, pose p's vertex i at p * vertices + i.
std::vector<BakedVertex> bakePoses(const scene::SkinnedModel& model, const std::vector<std::vector<Mat4>>& poses) {
  const size_t n = model.mesh.positions.size();
  std::vector<BakedVertex> baked(poses.size() * n);
  for (size_t p = 0; p < poses.size(); ++p) {
    const scene::Mesh posed = scene::skinMesh(model, poses[p]);
    for (size_t i = 0; i < n; ++i)
      baked[p * n + i] = {Vec4(posed.positions[i], 0.0f),
                          Vec4(posed.normals.empty() ? Vec3(0.0f) : posed.normals[i], 0.0f)};
  }
  return baked;
}

constexpr const char* kBaked = "#define FF_BAKED_POSES 1\n";  // skin.vert.glsl for Skinning::BakedPoses

// skin.vert.glsl + crowd.frag.glsl with the skinning's and the cut-out's defines and `extra`.
Program skinnedProgram(bool baked, bool cutout, const std::string& extra = "") {
  return Program::fromEmbedded("skin.vert.glsl", "crowd.frag.glsl",
                               std::string(baked ? kBaked : "") + (cutout ? "#define FF_CUTOUT 1\n" : "") + extra);
}

void setLight(const Program& p, const LightSettings& light) {
  Vec3 dir = light.direction;
  dir = glm::length(dir) > 0.0f ? glm::normalize(dir) : Vec3(0.0f, 0.0f, -1.0f);
  p.set("u_light_dir", dir);
  p.set("u_light_color", light.color);
  p.set("u_ambient", light.ambient);
}

}  // namespace

SkinnedGpuModel::SkinnedGpuModel(const scene::SkinnedModel& model, const Mat4& model_to_agent,
                                 const std::vector<std::vector<Mat4>>& poses,
                                 std::span<const scene::DeformingLevel> levels, Skinning skinning)
    : skinning_(skinning), model_to_agent_(model_to_agent), base_color_(model.base_color) {
  scene::validateSkinnedModel(model);
  joint_count_ = uint32_t(model.skeleton.joints.size());
  if (poses.empty()) throw Error(model.name, "no poses for the GPU palette");
  std::vector<Mat4> palette;
  palette.reserve(poses.size() * joint_count_);
  for (size_t p = 0; p < poses.size(); ++p) {
    if (poses[p].size() != joint_count_)
      throw Error(model.name, "pose " + std::to_string(p) + " has " + std::to_string(poses[p].size()) +
                                  " joint matrices for " + std::to_string(joint_count_) + " joints");
    palette.insert(palette.end(), poses[p].begin(), poses[p].end());
  }
  pose_count_ = uint32_t(poses.size());
  const size_t n = model.mesh.positions.size();
  vertex_count_ = uint32_t(n);
  std::vector<SkinVertex> vertices(n);
  for (size_t i = 0; i < n; ++i) {
    SkinVertex& v = vertices[i];
    const Vec3& p = model.mesh.positions[i];
    const Vec3 nn = model.mesh.normals.empty() ? Vec3(0.0f) : model.mesh.normals[i];
    const Vec2 uv = model.mesh.uvs.empty() ? Vec2(0.0f) : model.mesh.uvs[i];
    v = {{p.x, p.y, p.z}, {nn.x, nn.y, nn.z}, {uv.x, uv.y}, {}, {}};
    for (int k = 0; k < 4; ++k) {
      v.joints[k] = model.joints[i][size_t(k)];
      v.weights[k] = model.weights[i][k];
    }
  }
  // Every level's indices in one buffer, and its triangles' regions (read by gl_PrimitiveID from its first).
  std::vector<uint32_t> indices = model.mesh.indices;
  const size_t mesh_triangles = indices.size() / 3;
  std::vector<uint32_t> regions(mesh_triangles, 0u);
  for (size_t t = 0; t < model.regions.size() && t < regions.size(); ++t) regions[t] = model.regions[t];
  levels_.push_back({0, uint32_t(indices.size()), 0});
  for (size_t l = 0; l < levels.size(); ++l) {
    const scene::DeformingLevel& level = levels[l];
    if (level.source_triangles.size() * 3 != level.indices.size())
      throw Error(model.name, "level " + std::to_string(l + 1) + ": not one source triangle per triangle");
    levels_.push_back({uint32_t(indices.size()), uint32_t(level.indices.size()), uint32_t(regions.size())});
    for (uint32_t i : level.indices) {
      if (i >= n) throw Error(model.name, "level " + std::to_string(l + 1) + ": index past the vertices");
      indices.push_back(i);
    }
    for (uint32_t t : level.source_triangles) {
      if (t >= mesh_triangles)
        throw Error(model.name, "level " + std::to_string(l + 1) + ": source triangle out of range");
      regions.push_back(regions[t]);
    }
  }
  glCreateBuffers(1, &vbo_);
  glNamedBufferStorage(vbo_, GLsizeiptr(n * sizeof(SkinVertex)), vertices.data(), 0);
  glCreateBuffers(1, &ibo_);
  glNamedBufferStorage(ibo_, GLsizeiptr(std::max<size_t>(indices.size(), 1) * sizeof(uint32_t)), indices.data(), 0);
  glCreateBuffers(1, &palette_);
  size_t pose_bytes = 0;
  if (skinning == Skinning::BakedPoses) {
    const std::vector<BakedVertex> baked = bakePoses(model, poses);
    pose_bytes = std::max<size_t>(baked.size(), 1) * sizeof(BakedVertex);
    glNamedBufferStorage(palette_, GLsizeiptr(pose_bytes), baked.empty() ? nullptr : baked.data(), 0);
  } else {
    pose_bytes = palette.size() * sizeof(Mat4);
    glNamedBufferStorage(palette_, GLsizeiptr(pose_bytes), palette.data(), 0);
  }
  if (regions.empty()) regions.push_back(0u);
  glCreateBuffers(1, &regions_);
  glNamedBufferStorage(regions_, GLsizeiptr(regions.size() * sizeof(uint32_t)), regions.data(), 0);
  bytes_ = n * sizeof(SkinVertex) + indices.size() * sizeof(uint32_t) + pose_bytes + regions.size() * sizeof(uint32_t);
  glCreateVertexArrays(1, &vao_);
  glVertexArrayVertexBuffer(vao_, 0, vbo_, 0, sizeof(SkinVertex));
  glVertexArrayElementBuffer(vao_, ibo_);
  auto attrib = [&](GLuint loc, GLint size, GLenum type, size_t offset, bool integer) {
    glEnableVertexArrayAttrib(vao_, loc);
    if (integer)
      glVertexArrayAttribIFormat(vao_, loc, size, type, GLuint(offset));
    else
      glVertexArrayAttribFormat(vao_, loc, size, type, GL_FALSE, GLuint(offset));
    glVertexArrayAttribBinding(vao_, loc, 0);
  };
  attrib(0, 3, GL_FLOAT, offsetof(SkinVertex, position), false);
  attrib(1, 3, GL_FLOAT, offsetof(SkinVertex, normal), false);
  attrib(2, 2, GL_FLOAT, offsetof(SkinVertex, uv), false);
  attrib(3, 4, GL_UNSIGNED_SHORT, offsetof(SkinVertex, joints), true);
  attrib(4, 4, GL_FLOAT, offsetof(SkinVertex, weights), false);
  // The shader's cut-out test, albedo.a = base alpha x texel alpha < 0.5, over every texel (filtered values lie
  // between texels').
  cutout_ = base_color_.a < 0.5f;
  if (model.texture) {
    texture_ = Texture::fromImage(*model.texture, true);
    textured_ = true;
    bytes_ += texture_.byteSize();
    for (const image::Rgba8& t : model.texture->pixels())
      if (base_color_.a * float(t.a) / 255.0f < 0.5f) {
        cutout_ = true;
        break;
      }
  }
}

SkinnedGpuModel::~SkinnedGpuModel() {
  if (vao_) glDeleteVertexArrays(1, &vao_);
  const GLuint buffers[4] = {vbo_, ibo_, palette_, regions_};
  glDeleteBuffers(4, buffers);
}

ImpostorAtlasGpu::ImpostorAtlasGpu(const AtlasLayout& layout) : layout_(layout) {
  if (layout.azimuths < 1 || layout.elevations < 1 || layout.cell_width < 1 || layout.cell_height < 1 ||
      layout.frames < 1)
    throw Error("impostor atlas", "empty layout");
  GLint max_size = 0, max_layers = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
  glGetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &max_layers);
  if (layout.width() > max_size || layout.height() > max_size || layout.frames > max_layers)
    throw Error("impostor atlas", std::to_string(layout.width()) + " x " + std::to_string(layout.height()) + " x " +
                                      std::to_string(layout.frames) + " exceeds the GL limits");
  for (uint32_t* tex : {&albedo_, &normal_depth_}) {
    glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, tex);
    glTextureStorage3D(*tex, 1, GL_RGBA8, layout.width(), layout.height(), layout.frames);
    glTextureParameteri(*tex, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(*tex, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(*tex, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(*tex, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  }
  glCreateTextures(GL_TEXTURE_2D, 1, &depth_);
  glTextureStorage2D(depth_, 1, GL_DEPTH_COMPONENT32F, layout.width(), layout.height());
  glCreateFramebuffers(1, &fbo_);
  glNamedFramebufferTexture(fbo_, GL_DEPTH_ATTACHMENT, depth_, 0);
  const GLenum draw[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
  glNamedFramebufferDrawBuffers(fbo_, 2, draw);
}

ImpostorAtlasGpu::~ImpostorAtlasGpu() {
  if (fbo_) glDeleteFramebuffers(1, &fbo_);
  const GLuint tex[3] = {albedo_, normal_depth_, depth_};
  glDeleteTextures(3, tex);
}

size_t ImpostorAtlasGpu::byteSize() const {
  return size_t(layout_.width()) * size_t(layout_.height()) * size_t(layout_.frames) * 8;
}

namespace {
image::ColorImage readLayer(uint32_t tex, int w, int h, int layer) {
  image::ColorImage img(w, h);
  glGetTextureSubImage(tex, 0, 0, 0, layer, w, h, 1, GL_RGBA, GL_UNSIGNED_BYTE, GLsizei(img.pixelCount() * 4),
                       img.data());
  return img;
}
}  // namespace

image::ColorImage ImpostorAtlasGpu::readAlbedo(int layer) const {
  return readLayer(albedo_, layout_.width(), layout_.height(), layer);
}
image::ColorImage ImpostorAtlasGpu::readNormalDepth(int layer) const {
  return readLayer(normal_depth_, layout_.width(), layout_.height(), layer);
}

CrowdRenderer::CrowdRenderer()
    : skinned_{{skinnedProgram(false, false), skinnedProgram(false, true)},
               {skinnedProgram(true, false), skinnedProgram(true, true)}},
      skinned_depth_{{skinnedProgram(false, false, "#define FF_DEPTH_ONLY 1\n"),
                      skinnedProgram(false, true, "#define FF_DEPTH_ONLY 1\n")},
                     {skinnedProgram(true, false, "#define FF_DEPTH_ONLY 1\n"),
                      skinnedProgram(true, true, "#define FF_DEPTH_ONLY 1\n")}},
      capture_{skinnedProgram(false, true, "#define FF_CAPTURE 1\n"),
               skinnedProgram(true, true, "#define FF_CAPTURE 1\n")},
      impostor_(Program::fromEmbedded("multiview.vert.glsl", "multiview.frag.glsl")),
      impostor_blend_(Program::fromEmbedded("multiview.vert.glsl", "multiview.frag.glsl", "#define FF_BLEND_VIEWS 1")),
      impostor_depth_(Program::fromEmbedded("multiview.vert.glsl", "multiview.frag.glsl", "#define FF_DEPTH_ONLY 1")) {
  glCreateBuffers(1, &agents_);
  glCreateVertexArrays(1, &empty_vao_);
  glCreateBuffers(1, &tints_);
  const std::vector<Vec4> white(size_t(scene::kColorRegions), Vec4(1.0f));
  setRegionTints(white);
}

CrowdRenderer::~CrowdRenderer() {
  if (agents_) glDeleteBuffers(1, &agents_);
  if (tints_) glDeleteBuffers(1, &tints_);
  if (empty_vao_) glDeleteVertexArrays(1, &empty_vao_);
}

void CrowdRenderer::setRegionTints(std::span<const Vec4> tints) {
  if (tints.empty() || tints.size() % size_t(scene::kColorRegions) != 0)
    throw Error("crowd region tints", std::to_string(tints.size()) + " tints are not a whole number of outfits of " +
                                          std::to_string(scene::kColorRegions) + " regions");
  glNamedBufferData(tints_, GLsizeiptr(tints.size_bytes()), tints.data(), GL_STATIC_DRAW);
  outfits_ = uint32_t(tints.size() / size_t(scene::kColorRegions));
}

const Program& CrowdRenderer::program(const Program (&programs)[2][2], const SkinnedGpuModel& model) const {
  return programs[model.skinning_ == Skinning::BakedPoses ? 1 : 0][model.cutout_ ? 1 : 0];
}

void CrowdRenderer::bindModel(const Program& p, const SkinnedGpuModel& model) const {
  p.set("u_model_to_agent", model.model_to_agent_);
  if (model.skinning_ == Skinning::BakedPoses)
    p.set("u_vertex_count", model.vertex_count_);
  else
    p.set("u_joint_count", model.joint_count_);
  p.set("u_first_instance", 0u);
  p.set("u_first_triangle", 0u);
  p.set("u_base_color", model.base_color_);
  p.set("u_textured", model.textured_ ? 1 : 0);
  if (model.textured_) model.texture_.bind(0);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, model.palette_);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, tints_);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, model.regions_);
}

void CrowdRenderer::bindAtlas(const Program& p, const ImpostorAtlasGpu& atlas) const {
  const AtlasLayout& l = atlas.layout_;
  glUniform2f(p.uniformLocation("u_half_size"), l.half_size.x, l.half_size.y);
  p.set("u_centre", l.centre);
  p.set("u_first_instance", 0u);
  glUniform2i(p.uniformLocation("u_grid"), l.azimuths, l.elevations);
  p.set("u_radius", l.radius);
  glBindTextureUnit(0, atlas.albedo_);
  glBindTextureUnit(1, atlas.normal_depth_);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, tints_);
}

uint32_t CrowdRenderer::uploadAgents(std::span<const CrowdAgentGpu> agents) {
  // A fresh store per draw (orphaning): draws already queued keep reading the old one.
  glNamedBufferData(agents_, GLsizeiptr(agents.size_bytes()), agents.data(), GL_STREAM_DRAW);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, agents_);
  return agents_;
}

FrameStats CrowdRenderer::drawAgents(const Program& p, const SkinnedGpuModel& model, size_t count,
                                     size_t level) const {
  FF_CHECK(level < model.levels_.size());
  const SkinnedGpuModel::Level& l = model.levels_[level];
  p.set("u_first_triangle", l.first_triangle);
  glBindVertexArray(model.vao_);
  glDrawElementsInstanced(GL_TRIANGLES, GLsizei(l.index_count), GL_UNSIGNED_INT,
                          reinterpret_cast<const void*>(size_t(l.first_index) * sizeof(uint32_t)), GLsizei(count));
  glBindVertexArray(0);
  FrameStats stats;
  stats.draw_calls = 1;
  stats.triangles = model.triangleCount(level) * count;
  stats.objects = uint32_t(count);
  return stats;
}

FrameStats CrowdRenderer::drawSkinned(const Camera& camera, const SkinnedGpuModel& model,
                                      std::span<const CrowdAgentGpu> agents, const LightSettings& light,
                                      size_t level) {
  if (agents.empty() || model.indexCount() == 0) return {};
  for (const CrowdAgentGpu& a : agents) FF_CHECK(a.index < model.pose_count_);
  uploadAgents(agents);
  const Program& p = useSkinned(camera, model, light);
  glEnable(GL_CULL_FACE);
  return drawAgents(p, model, agents.size(), level);
}

FrameStats CrowdRenderer::drawImpostors(const Camera& camera, const ImpostorAtlasGpu& atlas,
                                        std::span<const CrowdAgentGpu> agents, const LightSettings& light,
                                        bool blend_views) {
  FrameStats stats;
  if (agents.empty()) return stats;
  const AtlasLayout& l = atlas.layout_;
  for (const CrowdAgentGpu& a : agents) FF_CHECK(a.index < uint32_t(l.frames) && a.view < uint32_t(l.azimuths * l.elevations));
  uploadAgents(agents);
  useImpostors(camera, atlas, light, blend_views);
  glBindVertexArray(empty_vao_);
  glDisable(GL_CULL_FACE);
  glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, GLsizei(agents.size()));
  glEnable(GL_CULL_FACE);
  glBindVertexArray(0);
  stats.draw_calls = 1;
  stats.triangles = 2 * agents.size();
  stats.objects = uint32_t(agents.size());
  return stats;
}

void CrowdRenderer::drawIndirect(uint32_t vao, uint32_t commands, size_t command_offset, bool indexed) const {
  glBindVertexArray(vao);
  glBindBuffer(GL_DRAW_INDIRECT_BUFFER, commands);
  const void* offset = reinterpret_cast<const void*>(command_offset);
  if (indexed) glMultiDrawElementsIndirect(GL_TRIANGLES, GL_UNSIGNED_INT, offset, 1, 0);
  else glMultiDrawArraysIndirect(GL_TRIANGLE_STRIP, offset, 1, 0);
  glBindBuffer(GL_DRAW_INDIRECT_BUFFER, 0);
  glBindVertexArray(0);
}

const Program& CrowdRenderer::useSkinned(const Camera& camera, const SkinnedGpuModel& model,
                                         const LightSettings& light) {
  const Program& p = program(skinned_, model);
  p.use();
  p.set("u_view_proj", camera.viewProjection());
  p.set("u_outfits", outfits_);
  bindModel(p, model);
  setLight(p, light);
  return p;
}

const Program& CrowdRenderer::useImpostors(const Camera& camera, const ImpostorAtlasGpu& atlas,
                                           const LightSettings& light, bool blend_views) {
  const AtlasLayout& l = atlas.layout_;
  const Program& p = blend_views ? impostor_blend_ : impostor_;
  p.use();
  p.set("u_view_proj", camera.viewProjection());
  p.set("u_eye", camera.eye);
  p.set("u_fixed_dir", Vec3(0.0f));
  p.set("u_outfits", outfits_);
  p.set("u_max_elevation", l.max_elevation);
  p.set("u_octahedral", l.octahedral ? 1 : 0);
  bindAtlas(p, atlas);
  setLight(p, light);
  return p;
}

FrameStats CrowdRenderer::drawSkinnedIndirect(const Camera& camera, const SkinnedGpuModel& model, uint32_t agents,
                                              size_t offset, size_t bytes, uint32_t commands, size_t command_offset,
                                              const LightSettings& light, size_t level) {
  FrameStats stats;
  FF_CHECK(level < model.levels_.size());
  if (model.levels_[level].index_count == 0 || bytes == 0) return stats;
  glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 1, agents, GLintptr(offset), GLsizeiptr(bytes));
  const Program& p = useSkinned(camera, model, light);
  p.set("u_first_triangle", model.levels_[level].first_triangle);
  glEnable(GL_CULL_FACE);
  drawIndirect(model.vao_, commands, command_offset, true);
  stats.draw_calls = 1;
  return stats;
}

FrameStats CrowdRenderer::drawImpostorsIndirect(const Camera& camera, const ImpostorAtlasGpu& atlas, uint32_t agents,
                                                size_t offset, size_t bytes, uint32_t commands,
                                                size_t command_offset, const LightSettings& light,
                                                bool blend_views) {
  FrameStats stats;
  if (bytes == 0) return stats;
  glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 1, agents, GLintptr(offset), GLsizeiptr(bytes));
  useImpostors(camera, atlas, light, blend_views);
  glDisable(GL_CULL_FACE);
  drawIndirect(empty_vao_, commands, command_offset, false);
  glEnable(GL_CULL_FACE);
  stats.draw_calls = 1;
  return stats;
}

void CrowdRenderer::capture(const SkinnedGpuModel& model, uint32_t pose, ImpostorAtlasGpu& atlas, int layer,
                            std::span<const CaptureView> views) {
  const AtlasLayout& l = atlas.layout_;
  FF_CHECK(pose < model.pose_count_ && layer >= 0 && layer < l.frames);
  glNamedFramebufferTextureLayer(atlas.fbo_, GL_COLOR_ATTACHMENT0, atlas.albedo_, 0, layer);
  glNamedFramebufferTextureLayer(atlas.fbo_, GL_COLOR_ATTACHMENT1, atlas.normal_depth_, 0, layer);
  FF_CHECK(glCheckNamedFramebufferStatus(atlas.fbo_, GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE);
  glBindFramebuffer(GL_FRAMEBUFFER, atlas.fbo_);
  glViewport(0, 0, l.width(), l.height());
  glDisable(GL_SCISSOR_TEST);
  glDisable(GL_BLEND);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glDepthMask(GL_TRUE);
  const float clear0[4] = {0, 0, 0, 0}, clear1[4] = {0.5f, 0.5f, 0.5f, 0.5f}, depth0 = 0.0f;
  glClearNamedFramebufferfv(atlas.fbo_, GL_COLOR, 0, clear0);
  glClearNamedFramebufferfv(atlas.fbo_, GL_COLOR, 1, clear1);
  glClearNamedFramebufferfv(atlas.fbo_, GL_DEPTH, 0, &depth0);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_GREATER);
  glEnable(GL_CULL_FACE);
  glFrontFace(GL_CCW);
  const CrowdAgentGpu origin;  // identity agent: pose set below
  CrowdAgentGpu agent = origin;
  agent.index = pose;
  uploadAgents(std::span<const CrowdAgentGpu>(&agent, 1));
  const Program& capture = capture_[model.skinning_ == Skinning::BakedPoses ? 1 : 0];
  capture.use();
  bindModel(capture, model);
  capture.set("u_capture_centre", l.centre);
  capture.set("u_capture_radius", l.radius);
  glBindVertexArray(model.vao_);
  for (const CaptureView& v : views) {
    FF_CHECK(v.cell >= 0 && v.cell < l.azimuths * l.elevations);
    glViewport((v.cell % l.azimuths) * l.cell_width, (v.cell / l.azimuths) * l.cell_height, l.cell_width,
               l.cell_height);
    capture.set("u_view_proj", v.view_proj);
    capture.set("u_capture_dir", v.to_camera);
    glDrawElementsInstanced(GL_TRIANGLES, GLsizei(model.indexCount()), GL_UNSIGNED_INT, nullptr, 1);
  }
  glBindVertexArray(0);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

FrameStats CrowdRenderer::drawSkinnedDepth(const Mat4& light_view_proj, const SkinnedGpuModel& model,
                                           std::span<const CrowdAgentGpu> agents, size_t level) {
  if (agents.empty() || model.indexCount() == 0) return {};
  for (const CrowdAgentGpu& a : agents) FF_CHECK(a.index < model.pose_count_);
  uploadAgents(agents);
  const Program& p = program(skinned_depth_, model);
  p.use();
  p.set("u_view_proj", light_view_proj);
  bindModel(p, model);
  return drawAgents(p, model, agents.size(), level);
}

FrameStats CrowdRenderer::drawImpostorDepth(const Mat4& light_view_proj, const Vec3& to_light,
                                            const ImpostorAtlasGpu& atlas, std::span<const CrowdAgentGpu> agents) {
  FrameStats stats;
  if (agents.empty()) return stats;
  const AtlasLayout& l = atlas.layout_;
  for (const CrowdAgentGpu& a : agents) FF_CHECK(a.index < uint32_t(l.frames) && a.view < uint32_t(l.azimuths * l.elevations));
  uploadAgents(agents);
  impostor_depth_.use();
  impostor_depth_.set("u_view_proj", light_view_proj);
  impostor_depth_.set("u_eye", Vec3(0.0f));
  impostor_depth_.set("u_fixed_dir", glm::normalize(to_light));
  bindAtlas(impostor_depth_, atlas);
  glBindVertexArray(empty_vao_);
  glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, GLsizei(agents.size()));
  glBindVertexArray(0);
  stats.draw_calls = 1;
  stats.triangles = 2 * agents.size();
  stats.objects = uint32_t(agents.size());
  return stats;
}

FrameStats CrowdRenderer::drawSkinnedDepthIndirect(const Mat4& light_view_proj, const SkinnedGpuModel& model,
                                                   uint32_t agents, size_t offset, size_t bytes, uint32_t commands,
                                                   size_t command_offset, size_t level) {
  FrameStats stats;
  FF_CHECK(level < model.levels_.size());
  if (model.levels_[level].index_count == 0 || bytes == 0) return stats;
  glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 1, agents, GLintptr(offset), GLsizeiptr(bytes));
  const Program& p = program(skinned_depth_, model);
  p.use();
  p.set("u_view_proj", light_view_proj);
  bindModel(p, model);
  p.set("u_first_triangle", model.levels_[level].first_triangle);
  drawIndirect(model.vao_, commands, command_offset, true);
  stats.draw_calls = 1;
  return stats;
}

FrameStats CrowdRenderer::drawImpostorDepthIndirect(const Mat4& light_view_proj, const Vec3& to_light,
                                                    const ImpostorAtlasGpu& atlas, uint32_t agents, size_t offset,
                                                    size_t bytes, uint32_t commands, size_t command_offset) {
  FrameStats stats;
  if (bytes == 0) return stats;
  glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 1, agents, GLintptr(offset), GLsizeiptr(bytes));
  impostor_depth_.use();
  impostor_depth_.set("u_view_proj", light_view_proj);
  impostor_depth_.set("u_eye", Vec3(0.0f));
  impostor_depth_.set("u_fixed_dir", glm::normalize(to_light));
  bindAtlas(impostor_depth_, atlas);
  drawIndirect(empty_vao_, commands, command_offset, false);
  stats.draw_calls = 1;
  return stats;
}

void CrowdRenderer::finish() const { glFinish(); }

}  // namespace farfield::gpu
