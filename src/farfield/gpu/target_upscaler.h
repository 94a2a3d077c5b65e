// A frame rendered at a lower resolution shown at the full one: one full-target draw that writes the colour
// (bilinear), the object ids and the depth (nearest texel) of a smaller RenderTarget over the whole of a larger one.
// It replaces two blits (glBlitFramebuffer takes one colour format at a time) and a clear: on llvmpipe a blit of
// 640 x 360 took about 1 ms, and the governor's resolution levels paid two a frame (docs/DESIGN-NOTES.md, "The
// governor's floor").
#pragma once

#include <cstdint>

#include "farfield/gpu/program.h"
#include "farfield/gpu/render_target.h"

namespace farfield::gpu {

class TargetUpscaler {
 public:
  TargetUpscaler();  // needs a current context
  ~TargetUpscaler();
  TargetUpscaler(const TargetUpscaler&) = delete;
  TargetUpscaler& operator=(const TargetUpscaler&) = delete;

  // What is scaled up. Depth costs the pass its early depth test (gl_FragDepth): on llvmpipe 0.45 ms of 1.6 at 640 x
  // 360; the ids a texel fetch, 0.3 ms. A frame shown at the full resolution needs colour (and Farfield's measurements
  // the ids); a pass drawn over it afterwards needs depth.
  enum class Channels { Color, ColorAndIds, All };
  // Writes every pixel of `to` from `from`: colour, ids unless Channels::Color (then `to`'s ids are cleared to 0), and
  // depth with Channels::All (else `to`'s depth is cleared to the far plane). No clear of `to` is needed first. GPU
  // work only, no wait. Leaves `to` bound for an opaque pass (RenderTarget::bindForOpaquePass).
  void draw(const RenderTarget& from, const RenderTarget& to, Channels channels = Channels::All);

 private:
  Program program_;
  uint32_t vao_ = 0;
  Program ids_program_;    // the same without depth
  Program color_program_;  // ... and without ids
};

}  // namespace farfield::gpu
