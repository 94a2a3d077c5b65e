#include "farfield/gpu/target_upscaler.h"

#include <epoxy/gl.h>

#include "farfield/core/check.h"

namespace farfield::gpu {

TargetUpscaler::TargetUpscaler()
    : program_(Program::fromEmbedded("upscale.vert.glsl", "upscale.frag.glsl",
                                     "#define FF_UPSCALE_IDS 1\n#define FF_UPSCALE_DEPTH 1")),
      ids_program_(Program::fromEmbedded("upscale.vert.glsl", "upscale.frag.glsl", "#define FF_UPSCALE_IDS 1")),
      color_program_(Program::fromEmbedded("upscale.vert.glsl", "upscale.frag.glsl")) {
  glCreateVertexArrays(1, &vao_);
}

TargetUpscaler::~TargetUpscaler() {
  if (vao_) glDeleteVertexArrays(1, &vao_);
}

void TargetUpscaler::draw(const RenderTarget& from, const RenderTarget& to, Channels channels) {
  FF_CHECK(from.width() > 0 && from.height() > 0 && to.width() > 0 && to.height() > 0);
  to.bindForOpaquePass();
  const Program& program = channels == Channels::All           ? program_
                           : channels == Channels::ColorAndIds ? ids_program_
                                                               : color_program_;
  if (channels == Channels::All) {
    glDepthFunc(GL_ALWAYS);  // every pixel's depth written, whatever the target held
  } else {
    const float far = 0.0f;  // reversed Z
    glClearNamedFramebufferfv(to.framebuffer(), GL_DEPTH, 0, &far);
    glDisable(GL_DEPTH_TEST);
  }
  if (channels == Channels::Color) {
    const GLuint none = 0;
    glClearNamedFramebufferuiv(to.framebuffer(), GL_COLOR, 1, &none);
    glColorMaski(1, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);  // the program writes no id
  }
  glDisable(GL_CULL_FACE);
  program.use();
  glProgramUniform2f(program.handle(), program.uniformLocation("u_from_per_to"),
                     float(from.width()) / float(to.width()), float(from.height()) / float(to.height()));
  glProgramUniform2i(program.handle(), program.uniformLocation("u_from_size"), from.width(), from.height());
  from.colorTexture().bind(0);
  if (channels != Channels::Color) from.idTexture().bind(1);
  from.depthTexture().bind(2);
  glBindVertexArray(vao_);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindVertexArray(0);
  to.bindForOpaquePass();  // the opaque pass's state back (depth test GL_GREATER, culling)
}

}  // namespace farfield::gpu
