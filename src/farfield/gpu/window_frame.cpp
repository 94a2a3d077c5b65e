#include "farfield/gpu/window_frame.h"

#include <epoxy/gl.h>

#include <algorithm>

namespace farfield::gpu {

void clearWindow(int width, int height, const Vec4& color) {
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glViewport(0, 0, width, height);
  glDisable(GL_SCISSOR_TEST);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glDepthMask(GL_TRUE);
  glClearColor(color.r, color.g, color.b, color.a);
  glClearDepth(1.0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
}

void showFrame(const RenderTarget& target, int width, int height) {
  // Both framebuffers have row 0 at the bottom, so a plain blit keeps the image upright.
  glDisable(GL_SCISSOR_TEST);
  glBlitNamedFramebuffer(target.framebuffer(), 0, 0, 0, target.width(), target.height(), 0, 0, width, height,
                         GL_COLOR_BUFFER_BIT, GL_LINEAR);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glViewport(0, 0, width, height);
}

image::ColorImage readWindow(int width, int height) {
  image::ColorImage out(width, height);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  glReadBuffer(GL_BACK);
  glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glPixelStorei(GL_PACK_ROW_LENGTH, 0);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, out.data());
  const size_t row = size_t(width);
  image::Rgba8* data = out.data();
  for (int y = 0; y < height / 2; ++y)
    std::swap_ranges(data + size_t(y) * row, data + size_t(y + 1) * row, data + size_t(height - 1 - y) * row);
  for (size_t i = 0; i < out.pixelCount(); ++i) data[i].a = 255;
  return out;
}

}  // namespace farfield::gpu
