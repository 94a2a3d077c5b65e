// A render target's depth pyramid built on the GPU (depth_pyramid.comp.glsl; the CPU's gpu::DepthPyramid): level 0
// is the target's depth texture, each texel of level k + 1 the farthest (smallest, reversed Z) of the 2 x 2 texels
// of level k it covers (sizes rounding up), levels 1.. the mips of one R32F texture. For occlusion tests in compute
// shaders (the GPU culler's and the GPU crowd's).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "farfield/gpu/program.h"
#include "farfield/gpu/render_target.h"

namespace farfield::gpu {

class GpuDepthPyramid {
 public:
  static constexpr int kMaxLevels = 16;
  static constexpr int kLevelsPerDispatch = 3;  // an invocation's 4 x 4 texels halved twice in registers
  GpuDepthPyramid();  // needs a current context
  ~GpuDepthPyramid();
  GpuDepthPyramid(const GpuDepthPyramid&) = delete;
  GpuDepthPyramid& operator=(const GpuDepthPyramid&) = delete;

  // Sizes the levels for a width x height target (allocating when the size changes); true when it changed.
  bool resize(int width, int height);
  // Builds the levels of what `target` holds now (resizing to it), up to kLevelsPerDispatch levels per compute
  // dispatch. No wait.
  void build(const RenderTarget& target);
  // Binds the target's depth (level 0) and the pyramid (levels 1.. as mips 0..) to two texture units.
  void bind(int depth_unit, int pyramid_unit) const;
  int levels() const { return int(level_size_.size()); }
  uint32_t texture() const { return texture_; }  // levels 1.. (0 when the target is 1 x 1)
  // Level sizes, x and y of level 0 first: for a uniform ivec2 array.
  std::vector<int> levelSizes() const;

 private:
  Program program_;
  uint32_t texture_ = 0, depth_ = 0;
  int width_ = 0, height_ = 0;
  bool sizes_uploaded_ = false;  // the shader's u_size holds level_size_
  std::vector<std::array<int, 2>> level_size_;
};

}  // namespace farfield::gpu
