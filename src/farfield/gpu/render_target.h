// Off-screen render target: colour RGBA8 + depth 32F + object id R32UI, with readback into image::Image.
#pragma once

#include <vector>

#include "farfield/gpu/texture.h"
#include "farfield/image/image.h"

namespace farfield::gpu {

class RenderTarget {
 public:
  RenderTarget() = default;
  RenderTarget(int width, int height);
  ~RenderTarget();
  RenderTarget(RenderTarget&& other) noexcept;
  RenderTarget& operator=(RenderTarget&& other) noexcept;
  RenderTarget(const RenderTarget&) = delete;
  RenderTarget& operator=(const RenderTarget&) = delete;

  int width() const { return width_; }
  int height() const { return height_; }
  void bind() const;  // binds the framebuffer and sets the viewport
  // bind(), plus the state of an opaque pass: depth test GL_GREATER (reversed Z) with writes, back-face culling of
  // counter-clockwise fronts, no blending or scissor, all colour and id channels written.
  void bindForOpaquePass() const;
  // Clears colour to the given value, ids to 0 and depth to 0 (far, reversed Z).
  void clear(const Vec4& color) const;

  // Readback; row 0 at the top.
  image::ColorImage readColor() const;
  image::DepthImage readDepth() const;  // window depth in [0,1], reversed Z: 0 = far/background
  image::IdImage readIds() const;
  // The depth attachment as GL stores it (row 0 at the bottom) into `rows`, resized to width x height: the
  // readback of a frame's own depth for occlusion culling, with no flip and no allocation once sized.
  void readDepthRows(std::vector<float>& rows) const;

  const Texture& colorTexture() const { return color_; }
  const Texture& depthTexture() const { return depth_; }
  const Texture& idTexture() const { return ids_; }
  uint32_t framebuffer() const { return fbo_; }

 private:
  int width_ = 0;
  int height_ = 0;
  uint32_t fbo_ = 0;
  Texture color_, depth_, ids_;
};

}  // namespace farfield::gpu
