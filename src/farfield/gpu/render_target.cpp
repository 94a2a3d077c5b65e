#include "farfield/gpu/render_target.h"

#include <epoxy/gl.h>

#include <algorithm>
#include <string>
#include <utility>

#include "farfield/core/error.h"

namespace farfield::gpu {

RenderTarget::RenderTarget(int width, int height)
    : width_(width),
      height_(height),
      color_(width, height, TextureFormat::Rgba8),
      depth_(width, height, TextureFormat::Depth32F),
      ids_(width, height, TextureFormat::R32UI) {
  color_.setClampToEdge();
  glCreateFramebuffers(1, &fbo_);
  glNamedFramebufferTexture(fbo_, GL_COLOR_ATTACHMENT0, color_.handle(), 0);
  glNamedFramebufferTexture(fbo_, GL_COLOR_ATTACHMENT1, ids_.handle(), 0);
  glNamedFramebufferTexture(fbo_, GL_DEPTH_ATTACHMENT, depth_.handle(), 0);
  const GLenum buffers[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
  glNamedFramebufferDrawBuffers(fbo_, 2, buffers);
  glNamedFramebufferReadBuffer(fbo_, GL_COLOR_ATTACHMENT0);
  const GLenum status = glCheckNamedFramebufferStatus(fbo_, GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    glDeleteFramebuffers(1, &fbo_);
    fbo_ = 0;
    throw Error("render target", std::to_string(width) + "x" + std::to_string(height) +
                                     " framebuffer incomplete (status " + std::to_string(status) + ")");
  }
}

RenderTarget::~RenderTarget() {
  if (fbo_) glDeleteFramebuffers(1, &fbo_);
}

RenderTarget::RenderTarget(RenderTarget&& other) noexcept
    : width_(std::exchange(other.width_, 0)),
      height_(std::exchange(other.height_, 0)),
      fbo_(std::exchange(other.fbo_, 0)),
      color_(std::move(other.color_)),
      depth_(std::move(other.depth_)),
      ids_(std::move(other.ids_)) {}

RenderTarget& RenderTarget::operator=(RenderTarget&& other) noexcept {
  if (this != &other) {
    if (fbo_) glDeleteFramebuffers(1, &fbo_);
    width_ = std::exchange(other.width_, 0);
    height_ = std::exchange(other.height_, 0);
    fbo_ = std::exchange(other.fbo_, 0);
    color_ = std::move(other.color_);
    depth_ = std::move(other.depth_);
    ids_ = std::move(other.ids_);
  }
  return *this;
}

void RenderTarget::bind() const {
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
  glViewport(0, 0, width_, height_);
}

void RenderTarget::bindForOpaquePass() const {
  bind();
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_GREATER);  // reversed Z: nearer is larger
  glDepthMask(GL_TRUE);
  glDisable(GL_BLEND);
  glDisable(GL_SCISSOR_TEST);
  glColorMaski(0, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glColorMaski(1, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glEnable(GL_CULL_FACE);
  glCullFace(GL_BACK);
  glFrontFace(GL_CCW);
}

void RenderTarget::clear(const Vec4& color) const {
  // Clears obey the write masks and the scissor test; open them so the whole target is cleared.
  glDisable(GL_SCISSOR_TEST);
  glColorMaski(0, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glColorMaski(1, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glDepthMask(GL_TRUE);
  glClearNamedFramebufferfv(fbo_, GL_COLOR, 0, glm::value_ptr(color));
  const GLuint zero_id[4] = {0, 0, 0, 0};
  glClearNamedFramebufferuiv(fbo_, GL_COLOR, 1, zero_id);
  const GLfloat far_depth = 0.0f;  // reversed Z: 0 is the far plane
  glClearNamedFramebufferfv(fbo_, GL_DEPTH, 0, &far_depth);
}

namespace {

// GL images have row 0 at the bottom; Farfield images at the top.
template <class T>
image::Image<T> readTexture(const Texture& texture, GLenum format, GLenum type) {
  image::Image<T> out(texture.width(), texture.height());
  glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glPixelStorei(GL_PACK_ROW_LENGTH, 0);
  glGetTextureImage(texture.handle(), 0, format, type, GLsizei(out.pixelCount() * sizeof(T)), out.data());
  const size_t row = size_t(out.width());
  T* data = out.data();
  for (int y = 0; y < out.height() / 2; ++y)
    std::swap_ranges(data + size_t(y) * row, data + size_t(y + 1) * row, data + size_t(out.height() - 1 - y) * row);
  return out;
}

}  // namespace

image::ColorImage RenderTarget::readColor() const {
  return readTexture<image::Rgba8>(color_, GL_RGBA, GL_UNSIGNED_BYTE);
}

image::DepthImage RenderTarget::readDepth() const {
  return readTexture<float>(depth_, GL_DEPTH_COMPONENT, GL_FLOAT);
}

void RenderTarget::readDepthRows(std::vector<float>& rows) const {
  rows.resize(size_t(width_) * size_t(height_));
  glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glPixelStorei(GL_PACK_ROW_LENGTH, 0);
  glGetTextureImage(depth_.handle(), 0, GL_DEPTH_COMPONENT, GL_FLOAT, GLsizei(rows.size() * sizeof(float)), rows.data());
}

image::IdImage RenderTarget::readIds() const { return readTexture<uint32_t>(ids_, GL_RED_INTEGER, GL_UNSIGNED_INT); }

}  // namespace farfield::gpu
