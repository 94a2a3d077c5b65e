#include "farfield/gpu/gpu_depth_pyramid.h"

#include <epoxy/gl.h>

#include <algorithm>

#include "farfield/core/check.h"

namespace farfield::gpu {

GpuDepthPyramid::GpuDepthPyramid() : program_(Program::computeFromEmbedded("depth_pyramid.comp.glsl")) {}

GpuDepthPyramid::~GpuDepthPyramid() {
  if (texture_) glDeleteTextures(1, &texture_);
}

std::vector<int> GpuDepthPyramid::levelSizes() const {
  std::vector<int> sizes;
  for (const auto& s : level_size_) sizes.insert(sizes.end(), {s[0], s[1]});
  return sizes;
}

bool GpuDepthPyramid::resize(int width, int height) {
  if (width == width_ && height == height_) return false;
  {
    width_ = width, height_ = height;
    sizes_uploaded_ = false;
    level_size_.assign(1, {width_, height_});
    while (level_size_.back()[0] > 1 || level_size_.back()[1] > 1)
      level_size_.push_back({(level_size_.back()[0] + 1) / 2, (level_size_.back()[1] + 1) / 2});
    FF_CHECK_MSG(int(level_size_.size()) <= kMaxLevels, "render target too large for the depth pyramid");
    if (texture_) glDeleteTextures(1, &texture_);
    texture_ = 0;
    if (level_size_.size() >= 2) {
      // GL's mip levels halve rounding down; levels rounding up fit in those of the next power of two.
      int pw = 1, ph = 1;
      while (pw < level_size_[1][0]) pw *= 2;
      while (ph < level_size_[1][1]) ph *= 2;
      glCreateTextures(GL_TEXTURE_2D, 1, &texture_);
      glTextureStorage2D(texture_, GLsizei(level_size_.size()) - 1, GL_R32F, pw, ph);
      glTextureParameteri(texture_, GL_TEXTURE_MIN_FILTER, GL_NEAREST_MIPMAP_NEAREST);
      glTextureParameteri(texture_, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
      glTextureParameteri(texture_, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
      glTextureParameteri(texture_, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    }
  }
  return true;
}

void GpuDepthPyramid::build(const RenderTarget& target) {
  depth_ = target.depthTexture().handle();
  resize(target.width(), target.height());
  const int levels = int(level_size_.size());
  if (levels < 2) return;
  if (!sizes_uploaded_) {  // the level sizes change with the target's only (resize)
    const std::vector<int> sizes = levelSizes();
    glProgramUniform2iv(program_.handle(), program_.uniformLocation("u_size[0]"), GLsizei(levels), sizes.data());
    sizes_uploaded_ = true;
  }
  program_.use();
  // The levels are written as images: those writes wait for earlier reads of the pyramid (the last frame's tests)
  // only across this barrier (OpenGL 4.6, 7.13.2: a write after a read; gl_barrier_check.h).
  glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
  glBindTextureUnit(2, depth_);
  // Up to kLevelsPerDispatch levels a dispatch (depth_pyramid.comp.glsl), each invocation one texel of the last.
  for (int first = 0; first + 1 < levels; first += kLevelsPerDispatch) {
    const int count = std::min(kLevelsPerDispatch, levels - 1 - first);
    program_.set("u_first", first);
    program_.set("u_count", count);
    if (first >= 1) glBindImageTexture(0, texture_, GLint(first - 1), GL_FALSE, 0, GL_READ_ONLY, GL_R32F);
    for (int j = 1; j <= count; ++j)
      glBindImageTexture(GLuint(j), texture_, GLint(first + j - 1), GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
    const auto& made = level_size_[size_t(first + count)];
    glDispatchCompute(GLuint(made[0] + 7) / 8, GLuint(made[1] + 7) / 8, 1);
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
  }
  glBindTextureUnit(2, 0);
}

void GpuDepthPyramid::bind(int depth_unit, int pyramid_unit) const {
  glBindTextureUnit(GLuint(depth_unit), depth_);
  glBindTextureUnit(GLuint(pyramid_unit), texture_);
}

}  // namespace farfield::gpu
