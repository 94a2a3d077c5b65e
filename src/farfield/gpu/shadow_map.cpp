#include "farfield/gpu/shadow_map.h"

#include <epoxy/gl.h>

#include <string>
#include <vector>

#include "farfield/core/check.h"
#include "farfield/core/error.h"
#include "farfield/core/screen_tiles.h"

namespace farfield::gpu {

ShadowMap::ShadowMap(int size) : size_(size) {
  GLint max_size = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
  if (size < 16 || size > max_size)
    throw Error("shadow map", "size " + std::to_string(size) + " outside 16.." + std::to_string(max_size));
  glCreateTextures(GL_TEXTURE_2D, 1, &depth_);
  glTextureStorage2D(depth_, 1, GL_DEPTH_COMPONENT32F, size, size);
  // Hardware comparison with bilinear filtering (the receivers' filter), clamped: outside the map, no caster.
  glTextureParameteri(depth_, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(depth_, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTextureParameteri(depth_, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
  glTextureParameteri(depth_, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
  const float border[4] = {1.0f, 1.0f, 1.0f, 1.0f};
  glTextureParameterfv(depth_, GL_TEXTURE_BORDER_COLOR, border);
  glTextureParameteri(depth_, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
  glTextureParameteri(depth_, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
  glCreateFramebuffers(1, &fbo_);
  glNamedFramebufferTexture(fbo_, GL_DEPTH_ATTACHMENT, depth_, 0);
  glNamedFramebufferDrawBuffer(fbo_, GL_NONE);
  glNamedFramebufferReadBuffer(fbo_, GL_NONE);
  FF_CHECK(glCheckNamedFramebufferStatus(fbo_, GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE);
}

ShadowMap::~ShadowMap() {
  if (fbo_) glDeleteFramebuffers(1, &fbo_);
  if (depth_) glDeleteTextures(1, &depth_);
}

void ShadowMap::bindForCasters() const {
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
  glViewport(0, 0, size_, size_);
  glDisable(GL_SCISSOR_TEST);
  glDisable(GL_BLEND);
  glDisable(GL_CULL_FACE);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  const float far_depth = 1.0f;
  glClearNamedFramebufferfv(fbo_, GL_DEPTH, 0, &far_depth);
}

ShadowReceiver::ShadowReceiver()
    : program_(Program::fromEmbedded("shadow_receive.vert.glsl", "shadow_receive.frag.glsl")) {
  glCreateFramebuffers(1, &fbo_);
  glCreateBuffers(1, &vbo_);
  glCreateVertexArrays(1, &vao_);
  glVertexArrayVertexBuffer(vao_, 0, vbo_, 0, sizeof(glm::ivec2));
  glEnableVertexArrayAttrib(vao_, 0);
  glVertexArrayAttribIFormat(vao_, 0, 2, GL_INT, 0);
  glVertexArrayAttribBinding(vao_, 0, 0);
}

ShadowReceiver::~ShadowReceiver() {
  if (fbo_) glDeleteFramebuffers(1, &fbo_);
  if (vao_) glDeleteVertexArrays(1, &vao_);
  if (vbo_) glDeleteBuffers(1, &vbo_);
}

void ShadowReceiver::apply(const Camera& camera, const ShadowMap& map, const ShadowProjection& projection,
                           const RenderTarget& target, const LightSettings& light, uint32_t agent_id_mask,
                           float bias_m, float max_distance_m, std::span<const glm::ivec4> regions) {
  const std::vector<glm::ivec4> tiles = tileCover(regions, target.width(), target.height(), kTile);
  if (tiles.empty()) return;  // nothing to shade
  std::vector<glm::ivec2> corners;  // two triangles per rectangle, pixel corners
  corners.reserve(tiles.size() * 6);
  for (const glm::ivec4& t : tiles)
    for (const glm::ivec2& c : {glm::ivec2(t.x, t.y), glm::ivec2(t.z, t.y), glm::ivec2(t.z, t.w), glm::ivec2(t.x, t.y),
                                glm::ivec2(t.z, t.w), glm::ivec2(t.x, t.w)})
      corners.push_back(c);
  glNamedBufferData(vbo_, GLsizeiptr(corners.size() * sizeof(glm::ivec2)), corners.data(), GL_STREAM_DRAW);
  // The target's colour alone (its depth and ids are read as textures: no feedback loop).
  glNamedFramebufferTexture(fbo_, GL_COLOR_ATTACHMENT0, target.colorTexture().handle(), 0);
  glNamedFramebufferDrawBuffer(fbo_, GL_COLOR_ATTACHMENT0);
  FF_CHECK(glCheckNamedFramebufferStatus(fbo_, GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
  glViewport(0, 0, target.width(), target.height());
  glDisable(GL_DEPTH_TEST);
  glDepthMask(GL_FALSE);
  glDisable(GL_CULL_FACE);
  glDisable(GL_SCISSOR_TEST);
  glEnable(GL_BLEND);
  glBlendFuncSeparate(GL_ZERO, GL_SRC_COLOR, GL_ZERO, GL_ONE);  // colour *= factor, alpha kept
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  program_.use();
  program_.set("u_inv_view_proj", glm::inverse(camera.viewProjection()));
  program_.set("u_light_view_proj", projection.view_proj);
  program_.set("u_bias", bias_m / std::max(projection.depth_range_m, 1e-6f));
  program_.set("u_agent_mask", agent_id_mask);
  Vec3 dir = light.direction;
  dir = glm::length(dir) > 0.0f ? glm::normalize(dir) : Vec3(0.0f, 0.0f, -1.0f);
  program_.set("u_light_dir", dir);
  program_.set("u_light_color", light.color);
  program_.set("u_ambient", light.ambient);
  program_.set("u_eye", camera.eye);
  program_.set("u_forward", camera.forward());
  program_.set("u_max_distance", max_distance_m);
  glUniform2f(program_.uniformLocation("u_size"), float(target.width()), float(target.height()));
  glBindTextureUnit(0, target.depthTexture().handle());
  glBindTextureUnit(1, target.idTexture().handle());
  glBindTextureUnit(2, map.depthTexture());
  glBindVertexArray(vao_);
  glDrawArrays(GL_TRIANGLES, 0, GLsizei(corners.size()));
  glBindVertexArray(0);
  // The target's depth and ids unbound again: a later pass that draws into the target with a shader declaring a
  // sampler at these units would otherwise hold them (a feedback loop if it samples them; gl_barrier_check.h).
  for (GLuint unit : {0u, 1u, 2u}) glBindTextureUnit(unit, 0);
  glDisable(GL_BLEND);
  glDepthMask(GL_TRUE);
  glEnable(GL_DEPTH_TEST);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

}  // namespace farfield::gpu
